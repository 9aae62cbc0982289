# Several objects at once (thesis Fig. 7.5a): a big glass sphere (128 voxels, as in the thesis)
# among eight small ones (32 voxels), clear and amber, in a ring on a table: nine objects in one
# shader (each binds two or three textures; their receiver maps are summed into one ground map,
# and one shader gets 32). A low sun lights them
# from one side; baked as one scene (lightsim SCENE.json), the big sphere's shadow and its caustic
# fall on the small sphere behind it, whose own caustic the floor gets, and the small ones shade
# one another along the light (lightsim/ALGORITHM.md "From box to box").
voxelize procedural:sphere,r=0.35 -o big_sphere.vol.json --res "$(res 128)"
voxelize procedural:sphere,r=0.12 -o small_clear.vol.json --res "$(res 32)"
voxelize procedural:sphere,r=0.12,sigma_a=0.4:1.6:4.5,name=amber -o small_amber.vol.json --res "$(res 32)"
sed 's/\(-[0-9]*\)\{0,1\}\.baked\.vol\.json/.vol.json/' SCENE.json >bake.json
timed bake "$bin/lightsim/lightsim" bake.json -o . --backend "$backend" $quiet
