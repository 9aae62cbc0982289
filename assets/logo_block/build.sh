# Glass block with an embedded absorbing logo (thesis Fig. 1.1, 7.2a). Seen obliquely, its side
# faces reflect totally from inside. Its blue shadow and caustic fall behind it on the ground.
voxelize procedural:logo_block -o logo_block.vol.json --res "$(res 88)" --bounds -0.6,-0.54,-1.0,0.9,0.55,0.35
lightsim logo_block.vol.json -o logo_block.baked.vol.json
