# The dense-flint prism in the sun, throwing a spectrum onto the floor (issue "One bake for the
# whole scene": the spectral bake). Lying on its side, its axis along z, it takes a low sun
# (29 degrees up) on one face at the angle of least deviation, and sends it down, bent 60-70
# degrees: violet most, red least (n_d = 1.75, Abbe number 20). Baked in 16 spectral bands, each
# with its own n(lambda), summed to RGB through the CIE 1931 matching functions: a smooth
# rainbow (3 bands would give three offset copies, red, green and blue).
voxelize procedural:prism,side=0.7,height=1,ior=1.75,abbe=20,name=flint -o prism.vol.json --res "$(res 96)"
sed 's/\.baked\.vol\.json/.vol.json/' SCENE.json >bake.json
timed bake "$bin/lightsim/lightsim" bake.json -o . --bands 16 --backend "$backend" $quiet
