// Resource limits checked before a volume is allocated, so that a malformed or hostile header
// fails with a clear InputError (exit 2, docs/programs.md) instead of an out-of-memory crash.
#pragma once

#include <cstdint>
#include <string>

#include <glm/glm.hpp>

namespace eik {

// Largest grid size per axis any reader accepts (issue "Foundation": volumes up to 1024³).
constexpr int kMaxVolumeAxis = 1024;

// The largest light power (W/m² of a directional light, W/sr of a point light) a bake accepts: its
// results are stored as 32-bit floats, and a caustic concentrates the light by orders of magnitude,
// so a light near the float limit overflows only after the whole bake (docs/programs.md).
constexpr double kMaxLightPower = 1e30;

// Is v representable as a finite 32-bit float (|v| ≤ FLT_MAX)? A number finite as a double but not
// as a float (1e39) would become +Inf in a field or a shader.
bool finiteAsFloat(double v);

// Memory this process may use: physical memory from sysconf, lowered to a cgroup v2 limit when
// one is set. The environment variable EIKONAL_MEMORY_LIMIT_BYTES overrides both (for tests).
std::uint64_t physicalMemoryBytes();

// Bytes needed by `components` float32 values per voxel on a grid of `dims` (no overflow for
// any positive dims up to INT_MAX per axis).
std::uint64_t fieldBytes(const glm::ivec3& dims, int components);

// Throws InputError("SOURCE: FIELD: ...") when an axis of `dims` is over kMaxVolumeAxis, or when
// `bytes` is more than physicalMemoryBytes(). Call before allocating anything of that size.
void checkGridLimits(const std::string& source, const std::string& field, const glm::ivec3& dims);
void checkMemoryLimit(const std::string& source, const std::string& field, std::uint64_t bytes);

// Human-readable byte count ("1.5 GiB", "512 MiB", "12 KiB", "100 bytes").
std::string formatBytes(std::uint64_t bytes);

}  // namespace eik
