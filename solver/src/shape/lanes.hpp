// shape/lanes.hpp — the vector lanes the shape functions compute in (internal).
//
// Four doubles (one AVX register, two SSE registers without AVX) and two
// doubles, with the few operations the 3-node shape functions need on
// them (max, min, abs, copysign, conversions of cell indices) and
// `fused`, the multiply-add the shape functions write out so that their
// rounding does not depend on where the compiler inlines them. Used by
// shape.hpp only.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#ifdef __AVX__
#include <immintrin.h>
#endif

namespace hmpm::shape {

/// Four doubles, one AVX register (two SSE registers without AVX): the
/// GCC/Clang vector extension, so the 3-node shape functions evaluate all
/// the nodes of an axis at once, and the tensor product forms a whole row of
/// the stencil per instruction (lane 3 is padding).
using Lanes = double __attribute__((vector_size(32)));

/// Two doubles, and two or four cell indices: the axes of a 2D or 3D
/// stencil in GIMP's eval_axes.
using Lanes2 = double __attribute__((vector_size(16)));
using Ints2 = std::int32_t __attribute__((vector_size(8)));
using Ints4 = std::int32_t __attribute__((vector_size(16)));

#ifdef __AVX__
// vmaxpd/vminpd (GCC otherwise compiles the clamps below to a compare and a
// blend); the operand order gives the ternaries' result for NaN as well.
inline Lanes lanes_max(Lanes a, Lanes b) {
  return _mm256_max_pd(b, a);
}
inline Lanes lanes_min(Lanes a, Lanes b) {
  return _mm256_min_pd(b, a);
}
inline Lanes2 lanes_max(Lanes2 a, Lanes2 b) {
  return _mm_max_pd(b, a);
}
/// |a| lane by lane (the sign bit cleared: one vandpd, not a negation and a maximum).
inline Lanes lanes_abs(Lanes a) {
  return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a);
}
inline Lanes2 lanes_abs(Lanes2 a) {
  return _mm_andnot_pd(_mm_set1_pd(-0.0), a);
}
/// |a| with the sign of b, lane by lane.
inline Lanes lanes_copysign(Lanes a, Lanes b) {
  const Lanes sign = _mm256_set1_pd(-0.0);
  return _mm256_or_pd(_mm256_andnot_pd(sign, a), _mm256_and_pd(sign, b));
}
inline Lanes2 lanes_copysign(Lanes2 a, Lanes2 b) {
  const Lanes2 sign = _mm_set1_pd(-0.0);
  return _mm_or_pd(_mm_andnot_pd(sign, a), _mm_and_pd(sign, b));
}
/// The cell indices as doubles (the padding lanes too).
inline Lanes2 to_doubles(Ints2 i) {
  __m128i v = _mm_setzero_si128();
  std::memcpy(&v, &i, sizeof i);  // the lower half
  return _mm_cvtepi32_pd(v);
}
inline Lanes to_doubles(Ints4 i) {
  return _mm256_cvtepi32_pd(reinterpret_cast<__m128i>(i));
}
/// Whether any of the first Count lanes of a comparison's mask is set.
template <int Count, class Mask>
inline bool any_lane(Mask m) {
  if constexpr (sizeof(Mask) == 16)
    return (_mm_movemask_pd(reinterpret_cast<__m128d>(m)) & ((1 << Count) - 1)) != 0;
  else
    return (_mm256_movemask_pd(reinterpret_cast<__m256d>(m)) & ((1 << Count) - 1)) != 0;
}
#else
inline Lanes2 to_doubles(Ints2 i) {
  return __builtin_convertvector(i, Lanes2);
}
inline Lanes to_doubles(Ints4 i) {
  return __builtin_convertvector(i, Lanes);
}
template <int Count, class Mask>
inline bool any_lane(Mask m) {
  bool any = false;
  for (int a = 0; a < Count; ++a) any |= m[a] != 0;
  return any;
}
template <class V>
inline V lanes_max(V a, V b) {
  return a < b ? b : a;
}
template <class V>
inline V lanes_min(V a, V b) {
  return b < a ? b : a;
}
template <class V>
inline V lanes_abs(V a) {
  return lanes_max(a, -a);
}
template <class V>
inline V lanes_copysign(V a, V b) {
  V r;
  for (int i = 0; i < static_cast<int>(sizeof(V) / sizeof(double)); ++i)
    r[i] = std::copysign(a[i], b[i]);
  return r;
}
#endif
/// The same for one value (the one-axis form of GIMP).
inline double lanes_max(double a, double b) {
  return std::max(a, b);
}
inline double lanes_copysign(double a, double b) {
  return std::copysign(a, b);
}
/// v in every lane.
inline Lanes splat(double v) {
  return Lanes{v, v, v, v};
}
/// a b + c in one rounding where the machine has FMA, else in two. The
/// shape functions write their multiply-adds out with these: GCC contracts
/// a product and a sum into one FMA or not by the code around them, so
/// the same formula inlined in two places (the first particle of a loop
/// and the ones after it) could round differently.
inline double fused(double a, double b, double c) {
#ifdef __FMA__
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}
#ifdef __FMA__
inline Lanes fused(Lanes a, Lanes b, Lanes c) {
  return _mm256_fmadd_pd(a, b, c);
}
inline Lanes2 fused(Lanes2 a, Lanes2 b, Lanes2 c) {
  return _mm_fmadd_pd(a, b, c);
}
#else
template <class V>
inline V fused(V a, V b, V c) {
  return a * b + c;
}
#endif
/// Stores the four lanes at `to` (which has room for them).
inline void store_lanes(double* to, Lanes v) {
  std::memcpy(to, &v, sizeof v);
}

}  // namespace hmpm::shape
