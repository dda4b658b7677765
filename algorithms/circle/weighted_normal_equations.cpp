#include "algorithms/circle/weighted_normal_equations.hpp"

#include <cstring>
#include <utility>

namespace facet {
namespace {

// Two doubles in one SSE2 register: the sums run in two lanes (even and odd rows) and are added
// at the end. The compiler does not vectorise a floating-point sum on its own (it may not reorder
// the additions), so the lanes are written out.
using Lanes = double __attribute__((vector_size(16)));

Lanes load(const double* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// The rows after the last even one, and the sums' two lanes added: shared by both builds of
// rowBlock, so that they round alike.
template <int B, bool pair>
void finishRowBlock(const double* const* cols, const double* weight, const double* residual,
                    std::ptrdiff_t i, std::ptrdiff_t n, double* first, double* second,
                    double& firstR, double& secondR) {
  for (; i < n; ++i) {  // an odd last row
    const double wa = weight[i] * cols[0][i];
    for (int j = 0; j < B; ++j) first[j] += wa * cols[j][i];
    firstR += wa * residual[i];
    if constexpr (pair) {
      const double wb = weight[i] * cols[1][i];
      for (int j = 1; j < B; ++j) second[j] += wb * cols[j][i];
      secondR += wb * residual[i];
    }
  }
}

// Rows a (and a + 1 when `pair`) of J^T W J and J^T W r, for the B columns a .. a + B - 1 handed
// in `cols`: 2 B + 1 sums, which fit the 16 registers but for a few at B = 8. B is a template
// argument so that the sums are registers, not an array in memory.
template <int B, bool pair>
void rowBlock(const double* const* cols, const double* __restrict weight,
              const double* __restrict residual, std::ptrdiff_t n, double* first, double* second,
              double& firstR, double& secondR) {
  Lanes a[B] = {}, b[B] = {}, ra = {}, rb = {};
  std::ptrdiff_t i = 0;
  for (; i + 2 <= n; i += 2) {
    const Lanes w = load(weight + i), r = load(residual + i);
    Lanes c[B];
    for (int j = 0; j < B; ++j) c[j] = load(cols[j] + i);
    const Lanes wa = w * c[0];
    for (int j = 0; j < B; ++j) a[j] += wa * c[j];
    ra += wa * r;
    if constexpr (pair) {
      const Lanes wb = w * c[1];
      for (int j = 1; j < B; ++j) b[j] += wb * c[j];
      rb += wb * r;
    }
  }
  for (int j = 0; j < B; ++j) first[j] = a[j][0] + a[j][1];
  firstR = ra[0] + ra[1];
  if constexpr (pair) {
    for (int j = 1; j < B; ++j) second[j] = b[j][0] + b[j][1];
    secondR = rb[0] + rb[1];
  }
  finishRowBlock<B, pair>(cols, weight, residual, i, n, first, second, firstR, secondR);
}

#if defined(__x86_64__)
// The same sums with AVX2: the lanes of two columns in one 256-bit register (column j's even and
// odd rows, then column j + 1's). Each lane takes the same products and additions in the same
// order as rowBlock's, so the sums agree to the bit (no FMA: the products are rounded as there),
// in about 40% fewer instructions: a multiply and an add serve two columns.
using Quad = double __attribute__((vector_size(32)));

template <int B, bool pair>
__attribute__((target("avx2"))) void rowBlockAvx2(const double* const* cols,
                                                  const double* __restrict weight,
                                                  const double* __restrict residual,
                                                  std::ptrdiff_t n, double* first, double* second,
                                                  double& firstR, double& secondR) {
  constexpr int P = (B + 1) / 2;  // pairs of columns; an odd B's last pair repeats its column
  Quad a[P] = {}, b[P] = {};
  Quad rab = {};  // J^T W r's two rows: row a's lanes, then row a + 1's
  std::ptrdiff_t i = 0;
  for (; i + 2 <= n; i += 2) {
    const Lanes w = load(weight + i), r = load(residual + i);
    const Quad w2 = __builtin_shufflevector(w, w, 0, 1, 0, 1);
    const Quad r2 = __builtin_shufflevector(r, r, 0, 1, 0, 1);
    Quad c[P];
    for (int p = 0; p < P; ++p)
      c[p] = __builtin_shufflevector(load(cols[2 * p] + i),
                                     load(cols[2 * p + 1 < B ? 2 * p + 1 : B - 1] + i), 0, 1, 2, 3);
    // w * c[0] in the low half, w * c[1] in the high half (with B = 1, w * c[0] again).
    const Quad wab = w2 * c[0];
    const Quad wa = __builtin_shufflevector(wab, wab, 0, 1, 0, 1);
    for (int p = 0; p < P; ++p) a[p] += wa * c[p];
    rab += wab * r2;
    if constexpr (pair) {
      const Quad wb = __builtin_shufflevector(wab, wab, 2, 3, 2, 3);
      for (int p = 0; p < P; ++p) b[p] += wb * c[p];
    }
  }
  for (int j = 0; j < B; ++j) first[j] = a[j / 2][2 * (j % 2)] + a[j / 2][2 * (j % 2) + 1];
  firstR = rab[0] + rab[1];
  if constexpr (pair) {
    for (int j = 1; j < B; ++j) second[j] = b[j / 2][2 * (j % 2)] + b[j / 2][2 * (j % 2) + 1];
    secondR = rab[2] + rab[3];
  }
  finishRowBlock<B, pair>(cols, weight, residual, i, n, first, second, firstR, secondR);
}

bool hasAvx2() {
  static const bool avx2 = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return avx2;
}
#endif

// rowBlock for B columns if there are B; a single column has no second row, so its block is
// never built as a pair.
template <bool pair, int B>
bool rowBlockIf(int columns, const double* const* cols, const double* weight,
                const double* residual, std::ptrdiff_t n, double* first, double* second,
                double& firstR, double& secondR) {
  if (columns != B) return false;
  constexpr bool twoRows = pair && B > 1;
#if defined(__x86_64__)
  if (hasAvx2()) {
    rowBlockAvx2<B, twoRows>(cols, weight, residual, n, first, second, firstR, secondR);
    return true;
  }
#endif
  rowBlock<B, twoRows>(cols, weight, residual, n, first, second, firstR, secondR);
  return true;
}

// rowBlock for a run-time column count 1..8 (others do nothing).
template <bool pair, int... B>
void rowBlockOf(std::integer_sequence<int, B...>, int columns, const double* const* cols,
                const double* weight, const double* residual, std::ptrdiff_t n, double* first,
                double* second, double& firstR, double& secondR) {
  (void)(rowBlockIf<pair, B>(columns, cols, weight, residual, n, first, second, firstR, secondR) ||
         ...);
}

template <bool pair>
void rowBlockOf(int columns, const double* const* cols, const double* weight,
                const double* residual, std::ptrdiff_t n, double* first, double* second,
                double& firstR, double& secondR) {
  rowBlockOf<pair>(std::integer_sequence<int, 1, 2, 3, 4, 5, 6, 7, 8>{}, columns, cols, weight,
                   residual, n, first, second, firstR, secondR);
}

// Rows a < rows (a pair at a time) of J^T W J and J^T W r, mirrored into their columns.
void normalRows(std::span<const double* const> columns, int rows, const double* weight,
                const double* residual, std::ptrdiff_t n, double* jtj, double* jtr) {
  const int k = static_cast<int>(columns.size());
  double first[8] = {}, second[8] = {};
  for (int a = 0; a < rows; a += 2) {
    const int b = k - a;  // columns a .. k - 1
    double firstR = 0.0, secondR = 0.0;
    if (b >= 2)
      rowBlockOf<true>(b, columns.data() + a, weight, residual, n, first, second, firstR, secondR);
    else
      rowBlockOf<false>(b, columns.data() + a, weight, residual, n, first, second, firstR, secondR);
    for (int j = 0; j < b; ++j) jtj[a * k + a + j] = jtj[(a + j) * k + a] = first[j];
    jtr[a] = firstR;
    if (b >= 2) {
      for (int j = 1; j < b; ++j) jtj[(a + 1) * k + a + j] = jtj[(a + j) * k + a + 1] = second[j];
      jtr[a + 1] = secondR;
    }
  }
}

}  // namespace

void weightedNormalEquations(std::span<const double* const> columns, const double* weight,
                             const double* residual, std::ptrdiff_t n, double* jtj, double* jtr) {
  normalRows(columns, static_cast<int>(columns.size()), weight, residual, n, jtj, jtr);
}

void weightedNormalEquationsLeadingPair(std::span<const double* const> columns,
                                        const double* weight, const double* residual,
                                        std::ptrdiff_t n, double* jtj, double* jtr) {
  normalRows(columns, 2, weight, residual, n, jtj, jtr);
}

}  // namespace facet
