# Amber Stanford bunny with dark embeddings, in scattering smoke, lit from below (thesis Fig. 7.3b).
# The bunny comes from the npm package "bunny" (scripts/fetch_assets.sh). Innermost wins: the dark
# opaque grains inside the bunny, the bunny inside the smoke.
voxelize "$ASSETS/meshes/bunny.obj" \
         procedural:sphere,r=0.05,center=-0.12:-0.2:0.08,albedo=0.04:0.03:0.02,name=grain \
         procedural:sphere,r=0.04,center=0.12:-0.3:-0.05,albedo=0.04:0.03:0.02,name=grain \
         procedural:sphere,r=0.035,center=-0.02:0.05:0.0,albedo=0.04:0.03:0.02,name=grain \
         procedural:box,size=1.5:1.3:1.3,center=0:0:0,ior=1,scatter=0.35,g=0.2,sigma_a=0.05:0.05:0.05,name=smoke \
         --material ior=1.55,sigma_a=0.25:0.9:2.8,scatter=0.6,g=0.3,name=amber \
         --material name=grain --material name=grain --material name=grain --material name=smoke \
         -o amber_bunny.vol.json --res "$(res 80)"
lightsim amber_bunny.vol.json -o amber_bunny.baked.vol.json
