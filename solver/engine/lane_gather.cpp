#include "lane_gather.hpp"

#include <cstddef>

#include "simd_level.hpp"

#if GS_SIMD_X86
#include <immintrin.h>
#endif

namespace gs::solver {

static_assert(sizeof(ContactHistory) % sizeof(double) == 0, "histories gathered in doubles");
static_assert(sizeof(ContactParams) % sizeof(double) == 0, "parameters gathered in doubles");
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "particle vectors packed in threes");

bool lane_gather_available() {
  return GS_SIMD_X86 && simd_level() == SimdLevel::Avx512;
}

#if GS_SIMD_X86

namespace {

/// A member's offset in doubles from the start of its record.
template <class T, class M>
std::ptrdiff_t doubles_from(const T& record, const M& member) {
  return (reinterpret_cast<const char*>(&member) - reinterpret_cast<const char*>(&record)) /
         static_cast<std::ptrdiff_t>(sizeof(double));
}

/// The products of the low 32 bits of each 64-bit lane (the indices are 32-bit). (The masked
/// form: the plain intrinsic passes an undefined vector that GCC 12 warns about.)
__attribute__((target("avx512f"))) inline __m512i mul32(__m512i x, __m512i y) {
  return _mm512_maskz_mul_epu32(0xff, x, y);
}

/// dst[0..8) = base[idx[l]] on the lanes of `mask`, zero on the others.
__attribute__((target("avx512f"))) inline void gather_to(double* dst, __mmask8 mask, __m512i idx,
                                                         const double* base) {
  _mm512_store_pd(dst, _mm512_mask_i64gather_pd(_mm512_setzero_pd(), mask, idx, base, 8));
}

/// dst[0..8) = base[idx[l]] on the lanes of `mask`; the others keep what dst holds.
__attribute__((target("avx512f"))) inline void gather_into(double* dst, __mmask8 mask, __m512i idx,
                                                           const double* base) {
  _mm512_store_pd(dst, _mm512_mask_i64gather_pd(_mm512_load_pd(dst), mask, idx, base, 8));
}

__attribute__((target("avx512f"))) void gather_lanes_avx512(
    const LaneSources& s, const std::int64_t* pair, const std::int64_t* a, const std::int64_t* b,
    std::uint32_t sphere, int count, ContactBatch& B) {
  using F = ContactBatch::Field;  // (F::X + c: the field c after X, as an int)
  const ContactHistory& h0 = s.hist[0];
  const double* hist = reinterpret_cast<const double*>(s.hist);
  const double* par = reinterpret_cast<const double*>(s.params);
  const std::ptrdiff_t o_normal = doubles_from(h0, h0.normal),
                       o_shear = doubles_from(h0, h0.shear_force),
                       o_bending = doubles_from(h0, h0.bending),
                       o_twist = doubles_from(h0, h0.twist);
  const std::ptrdiff_t o_real =
      reinterpret_cast<const char*>(&h0.real) - reinterpret_cast<const char*>(&h0);
  const ParticleState& p = *s.particles;
  const double* pos = p.pos.data()->data();
  const double* vel = p.vel.data()->data();
  const double* angvel = p.angvel.data()->data();
  const double* radius = p.radius.data();
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
  const __m512i hist_stride = _mm512_set1_epi64(sizeof(ContactHistory) / sizeof(double)),
                par_stride = _mm512_set1_epi64(sizeof(ContactParams) / sizeof(double)),
                hist_bytes = _mm512_set1_epi64(sizeof(ContactHistory)),
                three = _mm512_set1_epi64(3);
  for (int j0 = 0; j0 < count; j0 += 8) {
    const int n = count - j0 < 8 ? count - j0 : 8;
    const __mmask8 lanes = static_cast<__mmask8>((1u << n) - 1u);
    const __mmask8 spheres = static_cast<__mmask8>((sphere >> j0) & lanes);
    const __m512i k = _mm512_maskz_loadu_epi64(lanes, pair + j0);
    // The history and the parameters: every lane.
    // (pair and particle indices are 32-bit: the products of their low halves)
    const __m512i kh = mul32(k, hist_stride);
    const __m512i kp = mul32(k, par_stride);
    for (int c = 0; c < 3; ++c) {
      gather_to(&B.v[F::ONX + c][j0], lanes, kh, hist + o_normal + c);
      gather_to(&B.v[F::SX + c][j0], lanes, kh, hist + o_shear + c);
      gather_to(&B.v[F::BX + c][j0], lanes, kh, hist + o_bending + c);
      if (s.twist) gather_to(&B.v[F::TX + c][j0], lanes, kh, hist + o_twist + c);
    }
    // FRESH = h.real ? 0 : 1 (the bool's byte, read in the 8 bytes from it).
    const __m512i real_word = _mm512_mask_i64gather_epi64(
        _mm512_setzero_si512(), lanes,
        _mm512_add_epi64(mul32(k, hist_bytes), _mm512_set1_epi64(o_real)),
        reinterpret_cast<const char*>(s.hist), 1);
    const __mmask8 real = _mm512_mask_cmpneq_epi64_mask(
        lanes, _mm512_and_si512(real_word, _mm512_set1_epi64(0xff)), _mm512_setzero_si512());
    _mm512_store_pd(&B.v[F::FRESH][j0], _mm512_mask_blend_pd(real, one, zero));
    // (ContactParams: kn, ks, kr, ktw, tan_friction, max_roll, max_twist)
    gather_to(&B.v[F::KN][j0], lanes, kp, par + 0);
    gather_to(&B.v[F::KS][j0], lanes, kp, par + 1);
    gather_to(&B.v[F::KR][j0], lanes, kp, par + 2);
    if (s.ktw || s.twist) gather_to(&B.v[F::KTW][j0], lanes, kp, par + 3);
    gather_to(&B.v[F::TAN_FRICTION][j0], lanes, kp, par + 4);
    gather_to(&B.v[F::MAX_ROLL][j0], lanes, kp, par + 5);
    if (s.twist) gather_to(&B.v[F::MAX_TWIST][j0], lanes, kp, par + 6);
    if (spheres == 0) continue;
    // The bodies of the sphere pairs; the other lanes keep theirs.
    const __m512i ia = _mm512_maskz_loadu_epi64(spheres, a + j0),
                  ib = _mm512_maskz_loadu_epi64(spheres, b + j0);
    const __m512i ia3 = mul32(ia, three), ib3 = mul32(ib, three);
    for (int c = 0; c < 3; ++c) {
      gather_into(&B.v[F::X1X + c][j0], spheres, ia3, pos + c);
      gather_into(&B.v[F::X2X + c][j0], spheres, ib3, pos + c);
      gather_into(&B.v[F::V1X + c][j0], spheres, ia3, vel + c);
      gather_into(&B.v[F::V2X + c][j0], spheres, ib3, vel + c);
      gather_into(&B.v[F::W1X + c][j0], spheres, ia3, angvel + c);
      gather_into(&B.v[F::W2X + c][j0], spheres, ib3, angvel + c);
    }
    gather_into(&B.v[F::R1][j0], spheres, ia, radius);
    gather_into(&B.v[F::R2][j0], spheres, ib, radius);
    for (F f : {F::GEOM, F::RATCHET}) {
      double* dst = &B.v[f][j0];
      _mm512_store_pd(dst, _mm512_mask_blend_pd(spheres, _mm512_load_pd(dst), one));
    }
  }
}

}  // namespace

void gather_lanes(const LaneSources& s, const std::int64_t* pair, const std::int64_t* a,
                  const std::int64_t* b, std::uint32_t sphere, int count, ContactBatch& batch) {
  gather_lanes_avx512(s, pair, a, b, sphere, count, batch);
}

#else

void gather_lanes(const LaneSources&, const std::int64_t*, const std::int64_t*, const std::int64_t*,
                  std::uint32_t, int, ContactBatch&) {}

#endif

}  // namespace gs::solver
