# Dispersive prism (thesis Fig. 3.5b): an upright prism of dense flint (n_d = 1.75, Abbe number
# V_d = 20) in a city. Turned 50 degrees, one face sees the street near its critical angle, where
# red, green and blue viewing rays part most: a rainbow band beside the totally reflecting part.
# Its faces are sharp interfaces (voxelize's default), so Snell's law applies exactly at each. It
# floats with no ground and scatters nothing, so it needs no bake.
voxelize "$SCENE_DIR/prism.obj" --material ior=1.75,abbe=20,name=flint \
         -o prism.vol.json --res "$(res 96)"
