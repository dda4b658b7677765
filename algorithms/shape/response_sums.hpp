#pragma once
// The inner loop of the top-level search (internal to facet_shape): for a block of pixels of one
// row, the sum over a template's points of the response maps' values, each point read at its own
// offset. The sums stay in vector registers while all the points are added, so that every map
// value is loaded once per point and block.

#include <cstddef>
#include <cstdint>

namespace facet::shape_detail {

constexpr int kSumBlock = 64;  // pixels summed at once, at most
constexpr int kSumAlign = 16;  // block widths are a multiple of this

// out[x] = sum over i < count of row[offsets[i] + x], for 0 <= x < width: 8-bit values summed in
// 16 bits, saturating (the caller keeps the sums below 32767). width: a multiple of kSumAlign, at
// most kSumBlock.
// Uses AVX2 where the processor has it (the build itself targets the plain instruction set).
void sumResponses(const std::int8_t* row, const std::ptrdiff_t* offsets, std::size_t count,
                  int width, std::int16_t* out);

}  // namespace facet::shape_detail
