#include "algorithms/registration/transform_fit.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include <Eigen/Dense>

#include "algorithms/geometry/point_normaliser.hpp"
#include "algorithms/geometry/projective_map.hpp"
#include "algorithms/geometry/ransac.hpp"
#include "algorithms/geometry/similarity_fit.hpp"

namespace facet {
namespace {

int minimalSample(TransformModel model) {
  switch (model) {
    case TransformModel::Similarity:
      return 2;
    case TransformModel::Affine:
      return 3;
    case TransformModel::Homography:
      return 4;
  }
  return 4;
}

std::optional<cv::Matx33d> fitNormalised(const std::vector<cv::Point2d>& src,
                                         const std::vector<cv::Point2d>& dst,
                                         TransformModel model) {
  const int n = static_cast<int>(src.size());
  const cv::Matx33d Ts = pointNormaliser(src), Td = pointNormaliser(dst);
  std::vector<cv::Point2d> a(n), b(n);
  for (int i = 0; i < n; ++i) {
    a[i] = mapPoint(Ts, src[i]);
    b[i] = mapPoint(Td, dst[i]);
  }
  cv::Matx33d Hn = cv::Matx33d::eye();
  if (model == TransformModel::Homography && n == 4) {
    // Minimal sample: h33 = 1 and an 8x8 linear system (much cheaper than the SVD).
    Eigen::Matrix<double, 8, 8> M;
    Eigen::Matrix<double, 8, 1> r;
    for (int i = 0; i < 4; ++i) {
      const double x = a[i].x, y = a[i].y, u = b[i].x, v = b[i].y;
      M.row(2 * i) << x, y, 1, 0, 0, 0, -u * x, -u * y;
      M.row(2 * i + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y;
      r(2 * i) = u;
      r(2 * i + 1) = v;
    }
    const auto lu = M.fullPivLu();
    if (!lu.isInvertible()) return std::nullopt;
    const Eigen::Matrix<double, 8, 1> h = lu.solve(r);
    Hn = {h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1};
  } else if (model == TransformModel::Homography) {
    Eigen::MatrixXd M(2 * n, 9);
    for (int i = 0; i < n; ++i) {
      const double x = a[i].x, y = a[i].y, u = b[i].x, v = b[i].y;
      M.row(2 * i) << x, y, 1, 0, 0, 0, -u * x, -u * y, -u;
      M.row(2 * i + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y, -v;
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeFullV);
    const Eigen::VectorXd h = svd.matrixV().col(8);
    for (int k = 0; k < 9; ++k) Hn(k / 3, k % 3) = h(k);
  } else if (model == TransformModel::Affine) {
    Eigen::MatrixXd M(n, 3);
    Eigen::VectorXd u(n), v(n);
    for (int i = 0; i < n; ++i) {
      M.row(i) << a[i].x, a[i].y, 1;
      u(i) = b[i].x;
      v(i) = b[i].y;
    }
    const auto qr = M.colPivHouseholderQr();
    if (qr.rank() < 3) return std::nullopt;
    const Eigen::Vector3d pu = qr.solve(u), pv = qr.solve(v);
    Hn = {pu(0), pu(1), pu(2), pv(0), pv(1), pv(2), 0, 0, 1};
  } else {
    const auto similarity = fitSimilarity(a, b);
    if (!similarity) return std::nullopt;
    Hn = similarity->H;
  }
  cv::Matx33d H = Td.inv() * Hn * Ts;
  if (std::abs(H(2, 2)) < 1e-12) return std::nullopt;
  H *= 1.0 / H(2, 2);
  // A usable plane transform keeps orientation and does not collapse the plane.
  const double det = H(0, 0) * H(1, 1) - H(0, 1) * H(1, 0);
  if (!(det > 1e-8) || !std::isfinite(det)) return std::nullopt;
  return H;
}

std::vector<int> inliersOf(const cv::Matx33d& H, const std::vector<cv::Point2d>& src,
                           const std::vector<cv::Point2d>& dst, double threshold) {
  std::vector<int> in;
  for (std::size_t i = 0; i < src.size(); ++i)
    if (transferError(H, src[i], dst[i]) <= threshold) in.push_back(static_cast<int>(i));
  return in;
}

// Least squares on the pairs of the given indices.
std::optional<cv::Matx33d> fitSubset(const std::vector<int>& subset,
                                     const std::vector<cv::Point2d>& src,
                                     const std::vector<cv::Point2d>& dst, TransformModel model) {
  std::vector<cv::Point2d> s, d;
  for (int i : subset) {
    s.push_back(src[i]);
    d.push_back(dst[i]);
  }
  return fitTransformLeastSquares(s, d, model);
}

// Least squares on the inliers, re-selecting the inliers after each fit.
TransformFit polish(TransformFit fit, const std::vector<cv::Point2d>& src,
                    const std::vector<cv::Point2d>& dst, const TransformFitParams& params) {
  const auto minimal = static_cast<std::size_t>(minimalSample(params.model));
  for (int round = 0; round < 3; ++round) {
    if (fit.inliers.size() < minimal) break;
    const auto H = fitSubset(fit.inliers, src, dst, params.model);
    if (!H) break;
    std::vector<int> in = inliersOf(*H, src, dst, params.inlierThreshold);
    if (in.size() < fit.inliers.size()) break;
    const bool same = in == fit.inliers;
    fit = {*H, std::move(in)};
    if (same) break;
  }
  return fit;
}

// Twice the signed area of the triangle a, b, c.
double turn(cv::Point2d a, cv::Point2d b, cv::Point2d c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Whether the sample's triangles turn the same way in both images (always for two points).
bool keepsOrientation(const std::vector<std::size_t>& sample, const std::vector<cv::Point2d>& src,
                      const std::vector<cv::Point2d>& dst) {
  const std::size_t m = sample.size();
  for (std::size_t i = 0; i + 2 < m; ++i)
    for (std::size_t j = i + 1; j + 1 < m; ++j)
      for (std::size_t k = j + 1; k < m; ++k) {
        const double a = turn(src[sample[i]], src[sample[j]], src[sample[k]]);
        const double b = turn(dst[sample[i]], dst[sample[j]], dst[sample[k]]);
        if (!(a * b > 0)) return false;
      }
  return true;
}

// The next combination of sample.size() indices below n, in lexicographic order; false after
// the last.
bool nextCombination(std::vector<std::size_t>& sample, std::size_t n) {
  const std::size_t m = sample.size();
  for (std::size_t i = m; i-- > 0;)
    if (sample[i] < n - m + i) {
      ++sample[i];
      for (std::size_t j = i + 1; j < m; ++j) sample[j] = sample[j - 1] + 1;
      return true;
    }
  return false;
}

long combinations(std::size_t n, std::size_t m) {
  long c = 1;
  for (std::size_t k = 0; k < m; ++k) c = c * static_cast<long>(n - k) / static_cast<long>(k + 1);
  return c;
}

}  // namespace

bool parseTransformModel(const std::string& name, TransformModel& model) {
  if (name == "similarity")
    model = TransformModel::Similarity;
  else if (name == "affine")
    model = TransformModel::Affine;
  else if (name == "homography")
    model = TransformModel::Homography;
  else
    return false;
  return true;
}

double transferError(const cv::Matx33d& H, cv::Point2d src, cv::Point2d dst) {
  const double w = H(2, 0) * src.x + H(2, 1) * src.y + H(2, 2);
  if (!(std::abs(w) > 1e-12)) return std::numeric_limits<double>::infinity();
  const cv::Point2d q = mapPoint(H, src);
  return std::hypot(q.x - dst.x, q.y - dst.y);
}

std::optional<cv::Matx33d> fitTransformLeastSquares(const std::vector<cv::Point2d>& src,
                                                    const std::vector<cv::Point2d>& dst,
                                                    TransformModel model) {
  if (src.size() != dst.size() || static_cast<int>(src.size()) < minimalSample(model))
    return std::nullopt;
  return fitNormalised(src, dst, model);
}

std::optional<TransformFit> fitTransformRobust(const std::vector<cv::Point2d>& src,
                                               const std::vector<cv::Point2d>& dst,
                                               const TransformFitParams& params) {
  const auto minimal = static_cast<std::size_t>(minimalSample(params.model));
  if (src.size() != dst.size() || src.size() < minimal) return std::nullopt;
  RansacParams rp;
  rp.inlierThreshold = params.inlierThreshold;
  rp.confidence = params.confidence;
  rp.maxIterations = params.maxIterations;
  std::vector<cv::Point2d> s(minimal), d(minimal);
  auto fit = [&](const std::vector<std::size_t>& sample) -> std::optional<cv::Matx33d> {
    for (std::size_t k = 0; k < minimal; ++k) {
      s[k] = src[sample[k]];
      d[k] = dst[sample[k]];
    }
    return fitNormalised(s, d, params.model);
  };
  auto residual = [&](const cv::Matx33d& H, std::size_t i) {
    return transferError(H, src[i], dst[i]);
  };
  const auto r = ransac<cv::Matx33d>(src.size(), minimal, fit, residual, rp);
  if (!r) return std::nullopt;
  TransformFit out{r->model, {}};
  for (std::size_t i : r->inliers) out.inliers.push_back(static_cast<int>(i));
  return polish(std::move(out), src, dst, params);
}

std::optional<TransformFit> fitTransformWithLocalMaps(const std::vector<cv::Point2d>& src,
                                                      const std::vector<cv::Point2d>& dst,
                                                      const std::vector<cv::Matx22d>& localMaps,
                                                      const TransformFitParams& params) {
  // Plain RANSAC as one candidate; the seeded fits below do the heavy lifting when outliers
  // dominate, so it gets a smaller iteration budget.
  TransformFitParams plain = params;
  plain.maxIterations = std::min(params.maxIterations, 1000);
  std::optional<TransformFit> best = fitTransformRobust(src, dst, plain);
  const std::size_t n = src.size();
  const auto minimal = static_cast<std::size_t>(minimalSample(params.model));
  if (localMaps.size() != n || n < minimal) return best;
  // Score every single-match hypothesis by the matches it explains.
  struct Seed {
    std::size_t index;
    std::vector<int> support;
  };
  std::vector<Seed> seeds;
  for (std::size_t k = 0; k < n; ++k) {
    const cv::Matx22d& L = localMaps[k];
    std::vector<int> support;
    for (std::size_t i = 0; i < n; ++i) {
      const cv::Point2d d = src[i] - src[k];
      const cv::Point2d q(dst[k].x + L(0, 0) * d.x + L(0, 1) * d.y,
                          dst[k].y + L(1, 0) * d.x + L(1, 1) * d.y);
      const double tolerance =
          2.0 * params.inlierThreshold + 0.1 * std::sqrt(d.x * d.x + d.y * d.y);
      const double ex = q.x - dst[i].x, ey = q.y - dst[i].y;
      if (ex * ex + ey * ey <= tolerance * tolerance) support.push_back(static_cast<int>(i));
    }
    if (support.size() >= minimal + 1) seeds.push_back({k, std::move(support)});
  }
  std::sort(seeds.begin(), seeds.end(),
            [](const Seed& a, const Seed& b) { return a.support.size() > b.support.size(); });
  const std::size_t tries = std::min<std::size_t>(seeds.size(), 12);
  for (std::size_t t = 0; t < tries; ++t) {
    std::vector<cv::Point2d> s, d;
    for (int i : seeds[t].support) {
      s.push_back(src[i]);
      d.push_back(dst[i]);
    }
    const auto local = fitTransformRobust(s, d, params);
    if (!local) continue;
    TransformFit fit{local->H, inliersOf(local->H, src, dst, params.inlierThreshold)};
    fit = polish(std::move(fit), src, dst, params);
    if (!best || fit.inliers.size() > best->inliers.size()) best = std::move(fit);
  }
  return best;
}

std::vector<TransformFit> enumerateConsensusSets(const std::vector<cv::Point2d>& src,
                                                 const std::vector<cv::Point2d>& dst,
                                                 const TransformFitParams& params, int count,
                                                 long maxSamples) {
  const std::size_t n = src.size();
  const auto minimal = static_cast<std::size_t>(minimalSample(params.model));
  if (n != dst.size() || n < minimal + 1 || n > 64 || count <= 0 ||
      combinations(n, minimal) > maxSamples)
    return {};
  // Each sample's inlier set as a bit mask; a set is worth polishing when it holds more than the
  // sample that made it.
  std::vector<std::uint64_t> sets;
  std::vector<cv::Point2d> s(minimal), d(minimal);
  std::vector<std::size_t> sample(minimal);
  std::iota(sample.begin(), sample.end(), std::size_t{0});
  do {
    if (!keepsOrientation(sample, src, dst)) continue;
    for (std::size_t k = 0; k < minimal; ++k) {
      s[k] = src[sample[k]];
      d[k] = dst[sample[k]];
    }
    const auto H = fitNormalised(s, d, params.model);
    if (!H) continue;
    std::uint64_t set = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (transferError(*H, src[i], dst[i]) <= params.inlierThreshold) set |= std::uint64_t{1} << i;
    if (static_cast<std::size_t>(std::popcount(set)) > minimal) sets.push_back(set);
  } while (nextCombination(sample, n));
  std::sort(sets.begin(), sets.end());
  sets.erase(std::unique(sets.begin(), sets.end()), sets.end());
  std::stable_sort(sets.begin(), sets.end(), [](std::uint64_t a, std::uint64_t b) {
    return std::popcount(a) > std::popcount(b);
  });
  // Polished, sets that grow into one another become one; a few times `count` are polished so
  // that the merged ones leave enough distinct ones.
  struct Candidate {
    TransformFit fit;
    double squaredErrors;
  };
  std::vector<Candidate> candidates;
  const std::size_t polished =
      std::min<std::size_t>(sets.size(), 4 * static_cast<std::size_t>(count));
  for (std::size_t c = 0; c < polished; ++c) {
    TransformFit fit;
    for (std::size_t i = 0; i < n; ++i)
      if (sets[c] >> i & 1) fit.inliers.push_back(static_cast<int>(i));
    const auto H = fitSubset(fit.inliers, src, dst, params.model);
    if (!H) continue;
    fit.H = *H;
    fit = polish(std::move(fit), src, dst, params);
    if (fit.inliers.size() <= minimal) continue;
    double squared = 0;
    for (int i : fit.inliers) squared += std::pow(transferError(fit.H, src[i], dst[i]), 2);
    const bool seen = std::any_of(candidates.begin(), candidates.end(),
                                  [&](const Candidate& o) { return o.fit.inliers == fit.inliers; });
    if (!seen) candidates.push_back({std::move(fit), squared});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    if (a.fit.inliers.size() != b.fit.inliers.size())
      return a.fit.inliers.size() > b.fit.inliers.size();
    return a.squaredErrors < b.squaredErrors;
  });
  std::vector<TransformFit> out;
  for (std::size_t c = 0; c < candidates.size() && out.size() < static_cast<std::size_t>(count);
       ++c)
    out.push_back(std::move(candidates[c].fit));
  return out;
}

}  // namespace facet
