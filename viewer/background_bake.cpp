// The viewer window's background re-bake (see background_bake.h).
#include "viewer/background_bake.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <utility>

#include "core/error.h"
#include "core/stopwatch.h"
#include "lightsim/bake.h"
#include "lightsim/cpu_simulator.h"

namespace eik {

namespace {

glm::dvec3 jsonVec3(const nlohmann::json& a) {
  if (!a.is_array() || a.size() != 3) throw nlohmann::json::type_error::create(302, "expected three numbers", &a);
  return {a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>()};
}

}  // namespace

std::vector<RebakeSource> rebakeSources(const LoadedScene& scene) {
  std::vector<RebakeSource> sources;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const LoadedObject& object = scene.objects[i];
    const Volume& volume = object.volume;
    const nlohmann::json light = volume.metadata.value("light", nlohmann::json());
    if (!light.is_object() || light.value("type", std::string()) != "directional" || !(volume.has("irradiance") || !volume.receivers.empty()))
      continue;  // not baked by lightsim, or by a point light (the window moves a directional sun)
    RebakeSource s;
    s.object = static_cast<int>(i);
    s.source = object.source;
    s.object_to_world = object.object_to_world;
    try {
      s.light.type = LightSpec::Type::Directional;
      s.light.power = jsonVec3(light.at("irradiance"));
    } catch (const nlohmann::json::exception&) {
      throw InputError(object.source, "light", "the baked light is malformed");
    }
    if (!(s.light.power.x >= 0.0 && s.light.power.y >= 0.0 && s.light.power.z >= 0.0) ||
        !std::isfinite(s.light.power.x + s.light.power.y + s.light.power.z))
      throw InputError(object.source, "light.irradiance", "expected three finite numbers ≥ 0");

    // What `lightsim --scene` takes when the manifest does not say (bakes before "bake_options").
    SimulationOptions defaults;
    defaults.free_flight = true;
    const VolumeDefaults volume_defaults = volumeDefaults(volume.has("interfaces"), volume.grid);
    defaults.max_depth = volume_defaults.max_depth;
    defaults.patch_voxels = volume_defaults.patch_voxels;
    defaults.split_voxels = volume_defaults.split_voxels;
    // The bake runs in the object's bake frame, as `lightsim SCENE.json` bakes it: the scene's ground
    // carried into the volume's axes, lengths at world scale.
    s.frame = BakeFrame::of(object.object_to_world);
    if (scene.scene.ground) {
      ReceiverSpec ground;
      ground.point = scene.scene.ground->point;
      ground.normal = glm::normalize(scene.scene.ground->normal);
      ground.half_extent = scene.scene.ground->half_extent;
      defaults.receiver = s.frame.receiver(ground);
    }
    s.options = volume.metadata.contains("bake_options")
                    ? bakeOptionsFromJson(volume.metadata.at("bake_options"), object.source, defaults)
                    : defaults;
    // The plane is the scene's, wherever the manifest's bake had it (a bake of `lightsim VOLUME
    // --scene` records it in the volume's coordinates, unplaced).
    if (s.options.receiver && defaults.receiver) {
      s.options.receiver->point = defaults.receiver->point;
      s.options.receiver->normal = defaults.receiver->normal;
    }
    const nlohmann::json sigma = volume.metadata.value("irradiance_smoothing_sigma_voxels", nlohmann::json(0.0));
    s.smoothing_sigma = sigma.is_number() && std::isfinite(sigma.get<double>()) ? std::max(0.0, sigma.get<double>()) : 0.0;

    auto material = std::make_shared<Volume>(volume);
    material->fields.erase("irradiance");
    material->fields.erase("light_dir");
    material->receivers.clear();
    s.bake_material = s.frame.scale == 1.0 ? material : std::make_shared<Volume>(volumeAtWorldScale(*material, s.frame.scale));
    s.material = std::move(material);
    sources.push_back(std::move(s));
  }
  return sources;
}

SimulationOptions coarseOptions(SimulationOptions options) {
  options.patch_voxels *= 2.0;
  options.split_voxels *= 2.0;
  // The receiver's footprints cost in proportion to the texels they cover: a quarter as many.
  if (options.receiver) options.receiver->pitch_voxels = std::min(8.0, 2.0 * options.receiver->pitch_voxels);
  return options;
}

namespace {

LoadedObject rebakeWith(Simulator& simulator, const RebakeSource& source, glm::dvec3 world_direction,
                        BakeQuality quality, const std::atomic<bool>* cancel, ProgressFn progress,
                        SimulationStats* stats) {
  const double length = glm::length(world_direction);
  if (!(length > 0.0) || !std::isfinite(length)) throw std::invalid_argument("rebake: the light direction is zero");
  LightSpec world = source.light;
  world.direction = world_direction / length;
  LightSpec light = source.frame.light(world);
  SimulationOptions options = quality == BakeQuality::Coarse ? coarseOptions(source.options) : source.options;
  options.cancel = cancel;
  options.progress = std::move(progress);
  BakeResult result = simulator.run(light, options);
  bakeToVolumeFrame(result, light, source.frame.scale);
  if (source.smoothing_sigma > 0.0) smoothIrradiance(result, source.material->grid, source.smoothing_sigma);
  LoadedObject object;
  object.source = source.source;
  object.object_to_world = source.object_to_world;
  object.volume = *source.material;
  applyBake(object.volume, result, light);
  object.volume.metadata["bake_options"] = bakeOptionsToJson(options);
  if (stats) *stats = result.stats;
  return object;
}

}  // namespace

LoadedObject rebake(const RebakeSource& source, glm::dvec3 world_direction, BakeQuality quality,
                    const std::atomic<bool>* cancel, ProgressFn progress) {
  CpuSimulator simulator(*source.bake_material);
  return rebakeWith(simulator, source, world_direction, quality, cancel, std::move(progress), nullptr);
}

BackgroundBake::BackgroundBake(const LoadedScene& scene) : sources_(rebakeSources(scene)) {}

BackgroundBake::~BackgroundBake() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    cancel_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void BackgroundBake::request(glm::dvec3 world_direction, BakeQuality quality) {
  if (sources_.empty()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = Request{world_direction, quality, ++generation_};
    // A coarse bake under way finishes when another coarse one is asked for (something lands while
    // the slider is dragged); anything else is cancelled now.
    const bool let_finish = running_ && running_->quality == BakeQuality::Coarse && quality == BakeQuality::Coarse;
    if (running_ && !let_finish) cancel_ = true;
    error_.clear();
    if (!thread_.joinable()) thread_ = std::thread([this] { work(); });
  }
  wake_.notify_all();
}

std::vector<BackgroundBake::Landed> BackgroundBake::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Landed> out;
  out.swap(landed_);
  return out;
}

bool BackgroundBake::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return pending_.has_value() || running_.has_value();
}

double BackgroundBake::progress() const { return progress_.load(); }

BakeQuality BackgroundBake::runningQuality() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_ ? running_->quality : pending_ ? pending_->quality : BakeQuality::Full;
}

std::string BackgroundBake::lastError() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

void BackgroundBake::work() {
  // One CPU twin per object, made on first use (it copies n, ∇n and σa and builds its quiet map).
  std::vector<std::unique_ptr<CpuSimulator>> simulators(sources_.size());
  for (;;) {
    Request request;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      running_.reset();
      wake_.wait(lock, [this] { return stop_ || pending_.has_value(); });
      if (stop_) return;
      request = *pending_;
      pending_.reset();
      running_ = request;
      cancel_ = false;
    }
    progress_ = 0.0;
    const double share = 1.0 / static_cast<double>(sources_.size());
    for (std::size_t i = 0; i < sources_.size(); ++i) {
      const RebakeSource& source = sources_[i];
      try {
        if (!simulators[i]) simulators[i] = std::make_unique<CpuSimulator>(*source.bake_material);
        const Stopwatch watch;
        Landed landed;
        const double done = static_cast<double>(i) * share;
        landed.object = rebakeWith(*simulators[i], source, request.direction, request.quality, &cancel_,
                                   [this, done, share](double f) { progress_ = done + share * f; }, &landed.stats);
        landed.index = source.object;
        landed.quality = request.quality;
        landed.seconds = watch.seconds();
        // Landed even when a newer request waits (a coarse bake left to finish while dragging): it
        // is closer to the newest light than what is shown.
        std::lock_guard<std::mutex> lock(mutex_);
        landed_.push_back(std::move(landed));
        if (pending_) break;  // the newest light first
      } catch (const BakeCancelled&) {
        break;
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = source.source + ": " + e.what();
        break;
      }
    }
    progress_ = 1.0;
  }
}

}  // namespace eik
