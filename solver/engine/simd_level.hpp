// Which compiled variant of the vectorised batch kernels (contact law, integrator) runs:
// AVX-512, AVX2 or plain x86-64. Every variant gives the same bits (no fused multiply-adds; the
// operations of each lane in the order of the scalar expressions; docs/physics.md), so the choice
// changes speed only. By default the best level the CPU supports is taken at the first call;
// the environment variable GS_SIMD (avx512, avx2, generic) or set_simd_level() override it.
#pragma once

#include <atomic>
#include <optional>
#include <string_view>

// The AVX2 and AVX-512 variants exist on x86 only; elsewhere every level runs the plain code.
#if defined(__x86_64__) || defined(__i386__)
#define GS_SIMD_X86 1
#else
#define GS_SIMD_X86 0
#endif

namespace gs::solver {

enum class SimdLevel : int { Generic = 0, Avx2 = 1, Avx512 = 2 };

/// "generic", "avx2", "avx512".
const char* simd_level_name(SimdLevel level);
/// The inverse of simd_level_name; nullopt for any other string.
std::optional<SimdLevel> parse_simd_level(std::string_view name);
/// Whether this CPU (and its operating system) can run the variant: AVX-512F, AVX2.
bool simd_level_supported(SimdLevel level);
/// The best level this CPU supports.
SimdLevel best_simd_level();

/// Forces the variant the kernels use from now on (all threads). Throws std::invalid_argument
/// when the CPU cannot run it.
void set_simd_level(SimdLevel level);

namespace detail {
inline std::atomic<int> g_simd_level{-1};  // -1: not chosen yet
/// Chooses the level at the first call: GS_SIMD when set (an unknown name, or a level the CPU
/// lacks, is reported once on stderr and the best supported level not above it is taken), else
/// best_simd_level().
SimdLevel choose_simd_level();
}  // namespace detail

/// The variant the kernels use (chosen at the first call, see set_simd_level).
inline SimdLevel simd_level() {
  const int l = detail::g_simd_level.load(std::memory_order_relaxed);
  if (l < 0) [[unlikely]]
    return detail::choose_simd_level();
  return static_cast<SimdLevel>(l);
}

}  // namespace gs::solver
