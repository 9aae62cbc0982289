// voxelize: meshes (glTF 2.0, OBJ) and procedural shapes -> a material volume (docs/volume-format.md, docs/programs.md).
//
//   voxelize INPUT... -o OUT.vol.json [--res N] [--bounds ...] [--pad VOXELS] [--interfaces sharp|smooth]
//            [--smooth SIGMA]
//            [--material KEY=VALUE,...] [--stats FILE.json] [--quiet]
//
// This file only reads the command line; the work itself is voxelizeFiles (pipeline.h), which
// reports progress and writes the outputs.
#include <cstdio>
#include <string>

#include "core/cli.h"
#include "core/error.h"
#include "voxelize/grid_builder.h"
#include "voxelize/pipeline.h"
#include "voxelize/procedural.h"

namespace eik {
namespace {

std::string shapeHelp() {
  std::string out = "Procedural shapes (procedural:NAME[,key=value...]):\n";
  for (const auto& shape : proceduralShapes()) {
    out += "  " + shape.name + ": " + shape.description + "\n";
    for (const auto& p : shape.params)
      out += "      " + p.key + "=" + p.default_value + "  " + p.meaning + "\n";
    if (!shape.material_keys.empty()) {
      out += "      material keys:";
      for (const auto& k : shape.material_keys) out += " " + k;
      out += "\n";
    }
  }
  return out;
}

int run(int argc, char** argv) {
  VoxelizeOptions o;
  bool list_shapes = false;
  CLI::App app{
      "voxelize: turn meshes (glTF 2.0, OBJ) and procedural shapes into a material volume\n"
      "(refractive index n with sharp interfaces, or pre-smoothed with a Gaussian, its gradient,\n"
      "absorption, emission, scattering, opaque parts) for lightsim and viewer. Thesis §3.1 and §6.1.",
      "voxelize"};
  app.add_option("inputs", o.inputs,
                 "mesh.gltf | mesh.glb | mesh.obj | procedural:NAME[,key=value...] (several allowed; "
                 "see --list-shapes)");
  app.add_option("-o,--output", o.output, "output manifest, must end in .vol.json");
  app.add_option("--res", o.res, "voxels along the longest axis of the objects (default 128)")
      ->check(CLI::Range(1, kMaxGridDim));
  app.add_option("--bounds", o.bounds, "explicit world box MINX,MINY,MINZ,MAXX,MAXY,MAXZ (no padding added)");
  app.add_option("--pad", o.pad, "voxels of air around the objects (default 3)");
  app.add_option("--interfaces", o.interfaces,
                 "sharp (default: material boundaries stay sharp, recorded as signed distances; lightsim and "
                 "viewer apply Snell's law and Fresnel there) or smooth (the thesis: n pre-smoothed with a "
                 "Gaussian, Eq. 3.2)")
      ->check(CLI::IsMember({"sharp", "smooth"}));
  CLI::Option* smooth =
      app.add_option("--smooth", o.smooth,
                     "sigma of the Gaussian pre-smoothing of n in voxels, for --interfaces smooth (default 0.75; "
                     "0: none); given alone it selects --interfaces smooth");
  app.add_option("--material", o.materials,
                 "material of OBJ and procedural inputs: KEY=VALUE[,KEY=VALUE...] with keys ior, "
                 "sigma_a=R:G:B, emission=R:G:B, albedo=R:G:B (opaque), scatter, g, abbe, name. Given once "
                 "it applies to all of them, given several times the i-th applies to the i-th such input");
  app.add_option("--supersample", o.supersample, "sub-samples per voxel and axis for anti-aliased occupancy (default 4; a procedural shape with sharp interfaces and no absorbing, emitting, scattering, opaque or dispersive material takes one, at the voxel centre: only its reported volume reads the occupancy)")
      ->check(CLI::Range(1, 16));
  app.add_option("--surface", o.surface,
                 "how meshes are read: auto (open sheets become thin opaque receivers), solid, surface")
      ->check(CLI::IsMember({"auto", "solid", "surface"}));
  app.add_flag("--raw", o.raw, "write raw NRRD data instead of gzip");
  app.add_flag("--detached", o.detached, "write detached NRRD headers (.nhdr + .raw[.gz])");
  app.add_option("--scene", o.scene,
                 "also write a SCENE.json for the volume (default: OUT.scene.json when a glTF input has "
                 "lights or cameras)");
  app.add_option("--stats", o.stats, "write timings, voxel counts, volume per material, peak memory as JSON");
  app.add_flag("-q,--quiet", o.quiet, "no progress bar");
  app.add_flag("--list-shapes", list_shapes, "list the procedural shapes and their parameters");
  app.footer(
      "Examples:\n"
      "  voxelize procedural:sphere,r=0.5,ior=1.5 -o sphere.vol.json --res 128\n"
      "  voxelize glass.glb -o glass.vol.json --res 256\n"
      "  voxelize bunny.obj --material ior=1.55,sigma_a=0.2:0.6:1.4 -o bunny.vol.json\n"
      "Exit codes: 0 success, 1 runtime failure, 2 bad usage or bad input.");
  addOutsidePathsFlag(app);
  if (!parseCommandLine(app, argc, argv)) return kExitOk;
  if (smooth->count() > 0) {
    if (app.count("--interfaces") > 0 && o.interfaces == "sharp")
      throw InputError("--smooth", "", "smooths n, which --interfaces sharp keeps sharp: give one of them");
    o.interfaces = "smooth";
  }
  if (list_shapes) {
    std::printf("%s", shapeHelp().c_str());
    return kExitOk;
  }
  voxelizeFiles(o);
  return kExitOk;
}

}  // namespace
}  // namespace eik

int main(int argc, char** argv) { return eik::runMain("voxelize", eik::run, argc, argv); }
