# Glass sphere with a faint emissive core in an HDR environment (thesis Fig. 7.4a). The core is a
# second, smaller sphere: the innermost material wins. The box reaches below the ground (y = -0.5)
# and towards where the light goes, so the ground receives the sphere's caustic and shadow.
voxelize procedural:sphere,r=0.45,center=0:-0.05:0 \
         procedural:sphere,r=0.12,center=0:-0.05:0,emission=6:2.6:0.7,name=core \
         -o glass_sphere.vol.json --res "$(res 96)" --bounds -0.55,-0.53,-0.55,0.8,0.45,0.75
lightsim glass_sphere.vol.json -o glass_sphere.baked.vol.json
