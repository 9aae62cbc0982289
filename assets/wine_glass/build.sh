# Wine glass with red wine on a table: coloured caustics under a directional light (thesis Fig. 7.4b).
# The box reaches 6 voxels below the foot so the table (the ground plane at y = -0.5) lies inside
# the bake and receives the caustic and the shadow; it extends towards +x, where the light goes.
voxelize procedural:wine_glass,stem_radius=0.035,foot_thickness=0.04,wall=0.045 -o wine_glass.vol.json --res "$(res 96)" --bounds -0.45,-0.56,-0.55,1.1,0.54,0.4
lightsim wine_glass.vol.json -o wine_glass.baked.vol.json
