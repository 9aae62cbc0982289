// The SCENE.json that `voxelize` writes beside a volume (docs/scene-format.md): glTF lights
// (KHR_lights_punctual) and cameras converted to the programs' radiometric units, or a default
// camera and light that frame the volume.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/grid.h"
#include "core/scene.h"
#include "voxelize/mesh_scene.h"

namespace eik {

struct SceneExport {
  Scene scene;
  bool from_gltf = false;              // some input brought a light or a camera
  std::vector<std::string> warnings;   // what was approximated (none so far)
};

// Photometric → radiometric (docs/scene-format.md is linear radiometry): glTF gives a directional light's
// illuminance in lux and a point light's luminous intensity in candela. With 683 lm/W (the
// luminous efficacy at 555 nm, which Blender's exporter also uses: 1 W/m² ↦ 683 lux) the
// irradiance is E = color·lux/683 W/m² and the radiant intensity I = color·cd/683 W/sr.
glm::dvec3 irradianceFromLux(const glm::dvec3& color, double lux);
glm::dvec3 radiantIntensityFromCandela(const glm::dvec3& color, double candela);

// A scene with one object, the volume `manifest` (referenced by file name, as the scene is written
// beside it), the first glTF camera (or one that frames `grid`), and every glTF light (or one
// directional light from straight above).
SceneExport exportScene(const std::vector<MeshScene>& inputs, const std::filesystem::path& manifest,
                        const GridSpec& grid);

}  // namespace eik
