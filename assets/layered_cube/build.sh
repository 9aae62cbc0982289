# Layered rounded cube: three glasses with different n and colours that scatter a little, so the
# light focused inside them shows as volume caustics (thesis Fig. 1.2, 7.3a).
voxelize procedural:layered_cube,size=0.8,center=0:-0.1:0,scatter=1,g=0.3 \
         -o layered_cube.vol.json --res "$(res 88)" --bounds -0.75,-0.53,-0.65,0.5,0.35,0.5
lightsim layered_cube.vol.json -o layered_cube.baked.vol.json
