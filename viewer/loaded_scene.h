// A scene ready to render: the SCENE.json (core/scene.h, docs/scene-format.md) and every object's volume
// read from disk, placed by its transform. A bare VOLUME.vol.json is a scene too: that volume at
// the origin, a camera framing it, a white environment and the light it was baked with.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene.h"
#include "core/volume.h"
#include "viewer/camera.h"

namespace eik {

struct LoadedObject {
  std::string source;               // the manifest's path, for messages
  Volume volume;                    // has ior and ior_grad (checked)
  glm::dmat4 object_to_world{1.0};  // M of thesis §6.3.1
};

struct LoadedScene {
  Scene scene;                      // camera, environment, lights, ground, render settings
  std::vector<LoadedObject> objects;
  bool bare_volume = false;         // the input was a VOLUME.vol.json
  std::string source;               // the input's path, for messages

  Camera camera() const { return Camera::fromSpec(scene.camera); }
};


// A camera looking at the box from the front and a little above, the whole box in view.
SceneCameraSpec framingCamera(const GridSpec& grid, double fov_y_deg = 40.0);

// SCENE.json, or VOLUME.vol.json (by the ".vol.json" ending). InputError naming the file and the
// field for anything wrong: bad JSON, unknown keys, wrong types, no objects, a missing volume or
// one without ior / ior_grad.
LoadedScene loadScene(const std::filesystem::path& input);

struct SceneLoadOptions {
  // A headless render's: n and ∇n of a volume whose sharp materials all have a constant n are not
  // read (the shader takes each material's n and never samples them, and the analyses take n from
  // the interface distances, core/interfaces.h slotIndexAt; at 132³ 9 + 28 MB). The window (its
  // re-bake) and --bench (the bare march uploads them) read them.
  bool leave_constant_optics_unread = false;
};
LoadedScene loadScene(const std::filesystem::path& input, const SceneLoadOptions& options);

// In memory (tests): one volume as a bare-volume scene, or a scene with the given volumes in
// order of scene.objects (whose `volume` strings are then only names).
LoadedScene sceneFromVolume(Volume volume, const std::string& source = "volume");
LoadedScene sceneFromVolumes(Scene scene, std::vector<Volume> volumes);

}  // namespace eik
