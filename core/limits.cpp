#include "core/limits.h"

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string_view>

#include "core/error.h"

namespace eik {

bool finiteAsFloat(double v) { return std::isfinite(v) && std::fabs(v) <= static_cast<double>(std::numeric_limits<float>::max()); }
namespace {

// Parses a whole string as an unsigned decimal; false for anything else.
bool parseUnsigned(std::string_view text, std::uint64_t& value) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.remove_suffix(1);
  if (text.empty()) return false;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size();
}

// cgroup v2 memory limit of this process ("max" or absent: no limit).
std::uint64_t cgroupMemoryLimit() {
  std::ifstream file("/sys/fs/cgroup/memory.max");
  std::string line;
  std::uint64_t limit = 0;
  if (file && std::getline(file, line) && parseUnsigned(line, limit) && limit > 0) return limit;
  return UINT64_MAX;
}

}  // namespace

std::uint64_t physicalMemoryBytes() {
  if (const char* env = std::getenv("EIKONAL_MEMORY_LIMIT_BYTES")) {
    std::uint64_t value = 0;
    if (parseUnsigned(env, value)) return value;
    throw InputError("EIKONAL_MEMORY_LIMIT_BYTES", "", "'" + std::string(env) + "' is not a byte count");
  }
  long pages = sysconf(_SC_PHYS_PAGES);
  long page_size = sysconf(_SC_PAGE_SIZE);
  std::uint64_t physical = (pages > 0 && page_size > 0)
                               ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page_size)
                               : UINT64_MAX;
  std::uint64_t cgroup = cgroupMemoryLimit();
  return physical < cgroup ? physical : cgroup;
}

std::uint64_t fieldBytes(const glm::ivec3& dims, int components) {
  std::uint64_t bytes = sizeof(float) * static_cast<std::uint64_t>(components > 0 ? components : 0);
  for (int a = 0; a < 3; ++a) bytes *= static_cast<std::uint64_t>(dims[a] > 0 ? dims[a] : 0);
  return bytes;
}

void checkGridLimits(const std::string& source, const std::string& field, const glm::ivec3& dims) {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] > kMaxVolumeAxis) {
      throw InputError(source, field,
                       std::to_string(dims[a]) + " voxels along " + "xyz"[a] + " exceeds the limit of " +
                           std::to_string(kMaxVolumeAxis) + " voxels per axis");
    }
  }
}

void checkMemoryLimit(const std::string& source, const std::string& field, std::uint64_t bytes) {
  std::uint64_t available = physicalMemoryBytes();
  if (bytes > available) {
    throw InputError(source, field,
                     "needs " + formatBytes(bytes) + " of memory, more than the " + formatBytes(available) +
                         " this machine has (EIKONAL_MEMORY_LIMIT_BYTES overrides)");
  }
}

std::string formatBytes(std::uint64_t bytes) {
  static const char* const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double value = static_cast<double>(bytes);
  int unit = 0;
  while (value >= 1024.0 && unit < 6) {
    value /= 1024.0;
    ++unit;
  }
  char text[64];
  if (unit == 0) {
    std::snprintf(text, sizeof text, "%llu bytes", static_cast<unsigned long long>(bytes));
  } else {
    std::snprintf(text, sizeof text, "%.1f %s", value, units[unit]);
  }
  return text;
}

}  // namespace eik
