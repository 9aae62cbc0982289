# A wine glass under a point light (thesis Fig. 6.1: the glass met by a spherical wavefront from
# the right). The light, 1.2 units to the right of the glass and 1.3 up, sends a
# diverging wavefront through the wine and the glass: the floor gets its caustics, spread as the
# light's distance spreads them, and the inverse-square falloff of the light around them.
voxelize procedural:wine_glass,stem_radius=0.035,foot_thickness=0.04,wall=0.045 -o wine_glass.vol.json --res "$(res 96)"
sed 's/\.baked\.vol\.json/.vol.json/' SCENE.json >bake.json
timed bake "$bin/lightsim/lightsim" bake.json -o . --backend "$backend" $quiet
