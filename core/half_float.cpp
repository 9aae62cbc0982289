// Half-float conversion (see half_float.h).
#include "core/half_float.h"

#include <Imath/half.h>

#include <stdexcept>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <cpuid.h>
#include <immintrin.h>
#define EIK_HAVE_F16C_PATH 1
#endif

namespace eik {

#ifdef EIK_HAVE_F16C_PATH
namespace {

// Eight floats at a time by the F16C instruction (Ivy Bridge and later, every AVX2 CPU): the same
// rounding as Imath's (to nearest, ties to even; overflow to infinity; subnormal halves exact),
// some 30 times faster than a call a value. Chosen at run time; the tail and other CPUs take Imath.
__attribute__((target("avx,f16c"))) void toHalfF16c(const float* from, std::uint16_t* to, std::size_t n) {
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m128i h = _mm256_cvtps_ph(_mm256_loadu_ps(from + i), _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(to + i), h);
  }
  for (; i < n; ++i) to[i] = Imath::half(from[i]).bits();
}

bool hasF16c() {
  static const bool has = [] {
    __builtin_cpu_init();  // AVX: the CPU's and the operating system's (it saves the YMM registers)
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    const bool f16c = __get_cpuid(1, &eax, &ebx, &ecx, &edx) && (ecx & (1u << 29)) != 0;  // CPUID.1:ECX.F16C
    return __builtin_cpu_supports("avx") && f16c;
  }();
  return has;
}

}  // namespace
#endif

std::uint16_t toHalf(float value) { return Imath::half(value).bits(); }

void toHalf(std::span<const float> from, std::span<std::uint16_t> to) {
  if (from.size() != to.size()) throw std::invalid_argument("toHalf: the spans differ in length");
#ifdef EIK_HAVE_F16C_PATH
  if (hasF16c()) {
    toHalfF16c(from.data(), to.data(), from.size());
    return;
  }
#endif
  for (std::size_t i = 0; i < from.size(); ++i) to[i] = Imath::half(from[i]).bits();
}

float fromHalf(std::uint16_t bits) {
  Imath::half h;
  h.setBits(bits);
  return static_cast<float>(h);
}

}  // namespace eik
