# Dispersive prism (thesis Fig. 3.5b), n_d = 1.75, in front of a checkerboard: red, green and blue
# viewing rays part at its faces, so every edge seen through it shows a rainbow. The Abbe number
# V_d = 10 exaggerates a dense flint's (20-30) so the fringes show at this size. It floats with no
# ground and scatters nothing, so it needs no bake.
voxelize "$SCENE_DIR/prism.obj" --material ior=1.75,abbe=10,name=flint -o prism.vol.json --res "$(res 96)"
