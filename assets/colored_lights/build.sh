# Three coloured lights on one glass sphere (stage lighting, after the thesis' several-light scenes):
# a red, a green and a blue spot light from three sides, every one baked (lightsim SCENE.json sums
# the lights): each throws its own shadow and caustic in its colour, and where two shadows overlap
# the floor shows the colour the third one leaves.
voxelize procedural:sphere,r=0.35,center=0:-0.15:0 -o sphere.vol.json --res "$(res 64)" \
         --bounds -0.4,-0.53,-0.4,0.4,0.23,0.4
sed 's/\.baked\.vol\.json/.vol.json/' SCENE.json >bake.json
timed bake "$bin/lightsim/lightsim" bake.json -o . --backend "$backend" $quiet
