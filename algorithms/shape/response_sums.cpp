#include "algorithms/shape/response_sums.hpp"

#include <opencv2/core/hal/intrin.hpp>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define FACET_RESPONSE_SUMS_AVX2 1
#endif

namespace facet::shape_detail {
namespace {

// N registers of 8 lanes (OpenCV's universal intrinsics: SSE2, NEON, ...).
template <int N>
void sum128(const std::int8_t* row, const std::ptrdiff_t* offsets, std::size_t count,
            std::int16_t* out) {
  cv::v_int16x8 acc[N];
  for (auto& a : acc) a = cv::v_setzero_s16();
  for (std::size_t i = 0; i < count; ++i) {
    const std::int8_t* src = row + offsets[i];
    for (int k = 0; k < N; ++k) acc[k] += cv::v_load_expand(src + 8 * k);
  }
  for (int k = 0; k < N; ++k) cv::v_store(out + 8 * k, acc[k]);
}

#ifdef FACET_RESPONSE_SUMS_AVX2
// N registers of 16 lanes: half the instructions of sum128 for the same pixels.
template <int N>
__attribute__((target("avx2"))) void sum256(const std::int8_t* row, const std::ptrdiff_t* offsets,
                                            std::size_t count, std::int16_t* out) {
  __m256i acc[N];
  for (auto& a : acc) a = _mm256_setzero_si256();
  for (std::size_t i = 0; i < count; ++i) {
    const std::int8_t* src = row + offsets[i];
    for (int k = 0; k < N; ++k)
      acc[k] = _mm256_adds_epi16(
          acc[k],
          _mm256_cvtepi8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(src + 16 * k))));
  }
  for (int k = 0; k < N; ++k) _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 16 * k), acc[k]);
}

const bool kHasAvx2 = __builtin_cpu_supports("avx2");
#endif

}  // namespace

void sumResponses(const std::int8_t* row, const std::ptrdiff_t* offsets, std::size_t count,
                  int width, std::int16_t* out) {
  static_assert(kSumBlock == 4 * kSumAlign);
#ifdef FACET_RESPONSE_SUMS_AVX2
  if (kHasAvx2) {
    switch (width / 16) {
      case 1:
        return sum256<1>(row, offsets, count, out);
      case 2:
        return sum256<2>(row, offsets, count, out);
      case 3:
        return sum256<3>(row, offsets, count, out);
      default:
        return sum256<4>(row, offsets, count, out);
    }
  }
#endif
  switch (width / 16) {
    case 1:
      return sum128<2>(row, offsets, count, out);
    case 2:
      return sum128<4>(row, offsets, count, out);
    case 3:
      return sum128<6>(row, offsets, count, out);
    default:
      return sum128<8>(row, offsets, count, out);
  }
}

}  // namespace facet::shape_detail
