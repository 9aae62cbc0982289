# A museum shelf with several objects at once (thesis Fig. 7.5b): the wine glass, a glass sphere,
# the logo block and the layered cube, each in its own volume, placed by SCENE.json. Each box
# reaches below the ground (y = -0.5) and towards where the light goes (+x, -z), and no two boxes
# overlap once placed.
voxelize procedural:wine_glass,stem_radius=0.035,foot_thickness=0.04,wall=0.03 -o wine_glass.vol.json --res "$(res 64)" --bounds -0.3,-0.53,-0.6,0.5,0.5,0.3
voxelize procedural:sphere,r=0.3,center=0:-0.2:0 -o sphere.vol.json --res "$(res 56)" \
         --bounds -0.35,-0.53,-0.55,0.5,0.12,0.35
voxelize procedural:logo_block,size=0.6:0.6:0.3,center=0:-0.2:0 -o logo_block.vol.json --res "$(res 56)" \
         --bounds -0.35,-0.53,-0.55,0.5,0.12,0.2
voxelize procedural:layered_cube,size=0.5,center=0:-0.25:0,scatter=1,g=0.3 -o layered_cube.vol.json \
         --res "$(res 56)" --bounds -0.3,-0.53,-0.55,0.45,0.02,0.3
# One command bakes them all, each as SCENE.json places it (lightsim SCENE.json -o DIR): the scene
# with the volumes before their bake goes in, the baked volumes and SCENE.json come out here.
sed 's/\.baked\.vol\.json/.vol.json/' SCENE.json >bake.json
timed bake "$bin/lightsim/lightsim" bake.json -o . --backend "$backend" $quiet
