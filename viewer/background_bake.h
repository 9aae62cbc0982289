// The viewer window's re-bake (issue "fast on two CPU cores": drag the sun and the caustic follows):
// when the light's direction changes, every object of the scene that `lightsim` baked with a
// directional light is baked again with the new direction, in a background thread, with the CPU
// twin (lightsim/cpu_simulator.h) and the options its bake ran with (the manifest's "bake_options",
// lightsim/bake.h), so the window stays live. Each object's fresh volume lands as it finishes and
// the window swaps it in (SceneRenderer::replaceVolume).
//
// Progressive: a coarse bake (patches, split length and receiver texels twice as large)
// while the slider is dragged, the full one on release. A new request cancels a bake under way
// (SimulationOptions::cancel) except a coarse one while another coarse one is asked for: that one
// finishes first, so that something lands while dragging, and the newest request runs next.
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <glm/glm.hpp>

#include "lightsim/scene_bake.h"
#include "lightsim/simulator.h"
#include "viewer/loaded_scene.h"

namespace eik {

enum class BakeQuality { Coarse, Full };

// A re-bakeable object: its volume without the bake's fields, how it was baked, and its placement.
struct RebakeSource {
  int object = 0;                  // index in LoadedScene::objects
  std::string source;              // the manifest's path, for messages
  std::shared_ptr<const Volume> material;  // the volume less irradiance, light_dir and receivers
  // What the simulator bakes: `material` at world scale (lightsim/scene_bake.h), the same volume
  // where the object is not scaled.
  std::shared_ptr<const Volume> bake_material;
  glm::dmat4 object_to_world{1.0};
  BakeFrame frame;                 // the object's bake frame: the scene's light and ground in its axes
  LightSpec light;                 // as baked: directional, its irradiance
  SimulationOptions options;       // "bake_options", or lightsim's defaults for this volume
  double smoothing_sigma = 0.0;    // "irradiance_smoothing_sigma_voxels"
};

// The objects of `scene` that a directional light baked (manifest "light"), with their options:
// the manifest's "bake_options" when present, else what `lightsim --scene` takes (its defaults,
// free flight on, max depth 4 with sharp interfaces and 6 without, the scene's ground as the
// receiver in the volume's space). InputError naming the manifest for malformed "bake_options".
std::vector<RebakeSource> rebakeSources(const LoadedScene& scene);

// The options of a coarse bake: initial patch and split length doubled (a quarter of the patches
// at the start, about a third of the patch-steps) and the receiver map's texels twice as large (a
// quarter of the texels), the rest as given.
SimulationOptions coarseOptions(SimulationOptions options);

// The bake of `source` with a light travelling along `world_direction` (transformed into the
// volume's space), as a scene object ready for SceneRenderer::replaceVolume. Runs in the calling
// thread; throws BakeCancelled when `cancel` is set meanwhile.
LoadedObject rebake(const RebakeSource& source, glm::dvec3 world_direction, BakeQuality quality,
                    const std::atomic<bool>* cancel = nullptr, ProgressFn progress = {});

class BackgroundBake {
 public:
  explicit BackgroundBake(const LoadedScene& scene);  // rebakeSources(scene); starts no thread yet
  ~BackgroundBake();                                   // cancels and joins
  BackgroundBake(const BackgroundBake&) = delete;
  BackgroundBake& operator=(const BackgroundBake&) = delete;

  bool enabled() const { return !sources_.empty(); }  // any object to re-bake
  std::size_t objects() const { return sources_.size(); }

  // Asks for every object baked anew with this light direction (world, direction of travel).
  void request(glm::dvec3 world_direction, BakeQuality quality);

  struct Landed {
    LoadedObject object;
    int index = 0;        // in LoadedScene::objects
    BakeQuality quality = BakeQuality::Full;
    double seconds = 0.0;
    SimulationStats stats;
  };
  // The bakes of the newest request that finished since the last call (older ones are dropped).
  std::vector<Landed> take();

  bool busy() const;        // a request is pending or being baked
  double progress() const;  // of the bake under way, over all its objects, in [0, 1]
  BakeQuality runningQuality() const;
  std::string lastError() const;  // the message of a bake that failed (it is not retried), or ""

 private:
  struct Request {
    glm::dvec3 direction{0.0, -1.0, 0.0};
    BakeQuality quality = BakeQuality::Full;
    std::uint64_t generation = 0;
  };
  void work();

  std::vector<RebakeSource> sources_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Request> pending_;
  std::optional<Request> running_;
  std::uint64_t generation_ = 0;
  std::vector<Landed> landed_;
  std::string error_;
  bool stop_ = false;
  std::atomic<bool> cancel_{false};
  std::atomic<double> progress_{0.0};
  std::thread thread_;
};

}  // namespace eik
