// The tabulated edge profiles of the profile fit against their definitions, integrated
// numerically here: a lens profile is the Gaussian-blurred step averaged over the pixel square, a
// grid profile the pixel-averaged sharp step summed over the sampled Gaussian kernel. The tables
// use closed forms and interpolation; this checks both to float precision.
#include <cmath>
#include <memory>
#include <numbers>
#include <ostream>
#include <vector>

#include <gtest/gtest.h>

#include "algorithms/edges/edge_profile_tables.hpp"

namespace facet::edge_profile {
namespace {

double normalCdf(double x) {
  return 0.5 * std::erfc(-x / std::numbers::sqrt2);
}

double normalPdf(double x) {
  return std::exp(-0.5 * x * x) / std::sqrt(2 * std::numbers::pi);
}

// Gauss-Legendre nodes and weights on [-1/2, 1/2] (Newton on the Legendre polynomial).
struct Quadrature {
  std::vector<double> x, w;
};

Quadrature gaussLegendre(int n) {
  Quadrature q;
  for (int i = 1; i <= n; ++i) {
    double z = std::cos(std::numbers::pi * (i - 0.25) / (n + 0.5)), derivative = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      derivative = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / derivative;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    q.x.push_back(z / 2);
    q.w.push_back(1 / ((1 - z * z) * derivative * derivative));  // 2/(...) halved for [-1/2, 1/2]
  }
  return q;
}

// Value and slope (d/du) of the lens profile: Phi((u - x c - y s) / sigma) averaged over the
// pixel square.
void lensProfile(double u, double c, double s, double sigma, double& value, double& slope) {
  static const Quadrature q = gaussLegendre(40);
  value = slope = 0;
  for (size_t i = 0; i < q.x.size(); ++i)
    for (size_t j = 0; j < q.x.size(); ++j) {
      const double z = (u - q.x[i] * c - q.x[j] * s) / sigma;
      value += q.w[i] * q.w[j] * normalCdf(z);
      slope += q.w[i] * q.w[j] * normalPdf(z) / sigma;
    }
}

// The share of the pixel square with x c + y s < v (c >= s >= 0, c > 0), by the midpoint rule
// along y: each row is a clamped linear function of x.
double sharpStep(double v, double c, double s) {
  constexpr int kRows = 4000;
  double sum = 0;
  for (int k = 0; k < kRows; ++k) {
    const double y = (k + 0.5) / kRows - 0.5;
    sum += std::clamp((v - y * s) / c + 0.5, 0.0, 1.0);
  }
  return sum / kRows;
}

// The grid profile's value: the sharp step through the sampled Gaussian kernel (truncated at
// 4 sigma, normalised).
double gridValue(double u, double c, double s, double sigma) {
  const int r = static_cast<int>(std::ceil(4 * sigma));
  double total = 0, value = 0;
  for (int ky = -r; ky <= r; ++ky)
    for (int kx = -r; kx <= r; ++kx) {
      const double w = std::exp(-0.5 * (kx * kx + ky * ky) / (sigma * sigma));
      total += w;
      value += w * sharpStep(u - kx * c - ky * s, c, s);
    }
  return value / total;
}

struct Case {
  double sigma;
  int degrees;
};

void PrintTo(const Case& c, std::ostream* out) {
  *out << "sigma " << c.sigma << ", normal at " << c.degrees << " deg";
}

class ApertureProfileTable : public ::testing::TestWithParam<Case> {
 protected:
  // The table's row for the case's width and normal, with the normal it was asked for.
  struct Row {
    double c, s;
    std::shared_ptr<ApertureProfiles> profiles;  // holds the row the view points into
    ProfileView view;
  };
  Row row(bool gridBlur) const {
    const double angle = GetParam().degrees * std::numbers::pi / 180;
    Row r{std::cos(angle), std::sin(angle), apertureProfiles(GetParam().sigma, gridBlur), {}};
    r.view = apertureView(*r.profiles, {r.c, r.s});
    return r;
  }
};

TEST_P(ApertureProfileTable, LensRowMatchesTheBlurredStepOverThePixel) {
  const double sigma = GetParam().sigma;
  const auto [c, s, profiles, view] = row(false);
  ASSERT_NE(view.data, nullptr);
  for (int i = 0; i < view.size; i += 7) {
    const double u = i / view.perUnit - view.range;
    double value = 0, slope = 0;
    lensProfile(u, c, s, sigma, value, slope);
    EXPECT_NEAR(view.data[i].cdf, value, 1e-6) << "u " << u;
    EXPECT_NEAR(view.data[i].pdf, slope, 1e-6) << "u " << u;
  }
}

TEST_P(ApertureProfileTable, GridRowMatchesTheSharpStepThroughTheSampledKernel) {
  const double sigma = GetParam().sigma;
  const auto [c, s, profiles, view] = row(true);
  ASSERT_NE(view.data, nullptr);
  for (int i = 0; i < view.size; i += 11) {
    const double u = i / view.perUnit - view.range;
    EXPECT_NEAR(view.data[i].cdf, gridValue(u, c, s, sigma), 1e-6) << "u " << u;
  }
}

// The blur search reads rows every 5 degrees: a normal gets the row of the nearest multiple of
// 5 degrees of its nearest whole degree (folded into 0..45 like every row), the very row a normal
// at that multiple gets with the default step.
TEST(ApertureProfileTableByCoarseAngle, ReadsTheRowOfTheNearestMultiple) {
  for (const bool grid : {false, true}) {
    const auto profiles = apertureProfiles(0.74, grid);
    for (int degrees = -180; degrees < 180; ++degrees) {
      const double angle = (degrees + 0.3) * std::numbers::pi / 180;
      int folded = std::abs(degrees) % 90;
      if (folded > 45) folded = 90 - folded;
      const int multiple = (folded + 2) / 5 * 5;
      const double at = multiple * std::numbers::pi / 180;
      const ProfileView coarse = apertureView(*profiles, {std::cos(angle), std::sin(angle)}, 5);
      const ProfileView exact = apertureView(*profiles, {std::cos(at), std::sin(at)});
      EXPECT_EQ(coarse.data, exact.data) << degrees << " deg, grid " << grid;
    }
  }
}

// A width that an upstream estimate failed to give (NaN) yields a profile of NaN, which no fit
// prefers, never one of numbers.
TEST(ApertureProfileTableOfNoWidth, IsNotANumber) {
  const auto profiles = apertureProfiles(std::nan(""), false);
  const ProfileView view = apertureView(*profiles, {0.8, 0.6});
  ASSERT_NE(view.data, nullptr);
  for (int i = 0; i < view.size; i += 13) EXPECT_TRUE(std::isnan(view.data[i].cdf)) << i;
}

INSTANTIATE_TEST_SUITE_P(SigmasAndAngles, ApertureProfileTable,
                         ::testing::Values(Case{0.3, 0}, Case{0.3, 1}, Case{0.3, 45}, Case{0.8, 7},
                                           Case{0.8, 30}, Case{1.7, 0}, Case{1.7, 19},
                                           Case{1.7, 44}),
                         [](const auto& info) {
                           return "sigma" +
                                  std::to_string(static_cast<int>(info.param.sigma * 10)) + "_deg" +
                                  std::to_string(info.param.degrees);
                         });

}  // namespace
}  // namespace facet::edge_profile
