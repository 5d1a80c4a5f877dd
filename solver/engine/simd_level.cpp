#include "simd_level.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace gs::solver {

const char* simd_level_name(SimdLevel level) {
  switch (level) {
    case SimdLevel::Avx512:
      return "avx512";
    case SimdLevel::Avx2:
      return "avx2";
    case SimdLevel::Generic:
      break;
  }
  return "generic";
}

std::optional<SimdLevel> parse_simd_level(std::string_view name) {
  for (const SimdLevel l : {SimdLevel::Generic, SimdLevel::Avx2, SimdLevel::Avx512})
    if (name == simd_level_name(l)) return l;
  return std::nullopt;
}

bool simd_level_supported(SimdLevel level) {
#if GS_SIMD_X86
  __builtin_cpu_init();  // (libgcc's CPU model; it checks the OS saves the vector registers too)
  switch (level) {
    case SimdLevel::Avx512:
      return __builtin_cpu_supports("avx512f");
    case SimdLevel::Avx2:
      return __builtin_cpu_supports("avx2");
    case SimdLevel::Generic:
      return true;
  }
  return false;
#else
  return level == SimdLevel::Generic;
#endif
}

SimdLevel best_simd_level() {
  for (const SimdLevel l : {SimdLevel::Avx512, SimdLevel::Avx2})
    if (simd_level_supported(l)) return l;
  return SimdLevel::Generic;
}

void set_simd_level(SimdLevel level) {
  if (!simd_level_supported(level))
    throw std::invalid_argument(std::string("this CPU cannot run the ") + simd_level_name(level) +
                                " kernels");
  detail::g_simd_level.store(static_cast<int>(level), std::memory_order_relaxed);
}

namespace {

SimdLevel level_from_environment() {
  static const SimdLevel level = [] {
    const char* env = std::getenv("GS_SIMD");
    if (!env || !*env) return best_simd_level();
    const auto asked = parse_simd_level(env);
    if (!asked) {
      std::fprintf(stderr,
                   "warning: GS_SIMD=%s is not one of avx512, avx2, generic; using %s kernels\n",
                   env, simd_level_name(best_simd_level()));
      return best_simd_level();
    }
    SimdLevel l = *asked;
    while (!simd_level_supported(l)) l = static_cast<SimdLevel>(static_cast<int>(l) - 1);
    if (l != *asked)
      std::fprintf(stderr, "warning: GS_SIMD=%s: this CPU cannot run it; using %s kernels\n", env,
                   simd_level_name(l));
    return l;
  }();
  return level;
}

}  // namespace

SimdLevel detail::choose_simd_level() {
  int expected = -1;  // (a concurrent set_simd_level wins)
  g_simd_level.compare_exchange_strong(expected, static_cast<int>(level_from_environment()),
                                       std::memory_order_relaxed);
  return static_cast<SimdLevel>(g_simd_level.load(std::memory_order_relaxed));
}

}  // namespace gs::solver
