#pragma once
// FACET_PIXEL_PASS marks a loop over many pixels (elementwise arithmetic, no reductions): a
// second build of the function with AVX2, 4 pixels per instruction instead of SSE's 2, chosen
// when the program loads on a processor that has it. Without FMA the operations are the same, and
// so are the values.

#if defined(__x86_64__)
#define FACET_PIXEL_PASS __attribute__((target_clones("avx2", "default")))
#else
#define FACET_PIXEL_PASS
#endif
