// Which vector kernels of the analysis may run (the curl-curl product's AVX-512 variant, the
// AMG's AVX2 row sums): the CPU's support, capped by the environment variable GS_SIMD (generic,
// avx2, avx512) exactly as for the solver's kernels (solver/engine/simd_level.hpp, which the
// analysis does not include). Every variant gives the same bits; the choice changes speed only.
#pragma once

#include <cstdlib>
#include <cstring>

namespace gs::analysis {

enum class SimdCap : int { Generic = 0, Avx2 = 1, Avx512 = 2 };

/// The highest variant GS_SIMD allows (read once; unset or any other name: no cap).
inline SimdCap simd_cap() {
  static const SimdCap cap = [] {
    const char* s = std::getenv("GS_SIMD");
    if (s && std::strcmp(s, "generic") == 0) return SimdCap::Generic;
    if (s && std::strcmp(s, "avx2") == 0) return SimdCap::Avx2;
    return SimdCap::Avx512;
  }();
  return cap;
}

/// Whether the variant may run here: the CPU has it and GS_SIMD allows it.
inline bool simd_allowed(SimdCap level) {
  if (static_cast<int>(simd_cap()) < static_cast<int>(level)) return false;
#if defined(__x86_64__) || defined(__i386__)
  switch (level) {
    case SimdCap::Generic:
      return true;
    case SimdCap::Avx2:
      return __builtin_cpu_supports("avx2");
    case SimdCap::Avx512:
      return __builtin_cpu_supports("avx512f");
  }
  return false;
#else
  return level == SimdCap::Generic;
#endif
}

}  // namespace gs::analysis
