#pragma once
// FACET_PIXEL_PASS marks a loop over many pixels (elementwise arithmetic, no reductions): a
// second build of the function with AVX2, 4 pixels per instruction instead of SSE's 2, chosen
// when the program loads on a processor that has it. Without FMA the operations are the same, and
// so are the values. Loops over runs of a dozen pixels are written out with the lanes below,
// four at a time: the compiler's own vectorisation spent more instructions in set-up and
// remainder than in its vector body there.

#if defined(__x86_64__)
#define FACET_PIXEL_PASS __attribute__((target_clones("avx2", "default")))
#else
#define FACET_PIXEL_PASS
#endif

namespace facet::pixel_pass {

using Doubles4 = double __attribute__((vector_size(32)));
using Ints4 = int __attribute__((vector_size(16)));

// The lanes (0, 1, 2, 3): added to a column x0 (converted), the columns x0 .. x0 + 3 exactly.
inline constexpr Doubles4 kLane = {0.0, 1.0, 2.0, 3.0};

}  // namespace facet::pixel_pass
