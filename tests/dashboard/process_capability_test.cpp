#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "service/daemon/process_capability.hpp"

namespace facet::service {
namespace {

PartResult part(double diameter, double score) {
  PartResult p;
  p.measurements.push_back({.name = "bore.diameter",
                            .value = diameter,
                            .unit = "mm",
                            .nominal = 10.0,
                            .tolMinus = 0.1,
                            .tolPlus = 0.2,
                            .checked = true});
  Measurement scoreValue;  // reported, not checked
  scoreValue.name = "part.score";
  scoreValue.value = score;
  scoreValue.unit = "score";
  p.measurements.push_back(scoreValue);
  return p;
}

TEST(ProcessCapability, MeanSigmaCpCpkOfAKnownSeries) {
  // 9.95, 10.00, 10.05, 10.10: mean 10.025, sample sigma sqrt(0.00416667) = 0.0645497.
  const std::vector<PartResult> parts{part(9.95, 0.9), part(10.00, 0.8), part(10.05, 0.95),
                                      part(10.10, 0.85)};
  const auto caps = processCapability(parts);
  ASSERT_EQ(caps.size(), 2u);
  const Capability& d = caps[0];
  EXPECT_EQ(d.name, "bore.diameter");
  EXPECT_EQ(d.count, 4u);
  EXPECT_NEAR(d.mean, 10.025, 1e-12);
  EXPECT_NEAR(d.sigma, 0.0645497224, 1e-9);
  ASSERT_TRUE(d.lower && d.upper && d.cp && d.cpk);
  EXPECT_NEAR(*d.lower, 9.9, 1e-12);
  EXPECT_NEAR(*d.upper, 10.2, 1e-12);
  EXPECT_NEAR(*d.cp, 0.3 / (6 * 0.0645497224), 1e-8);
  // Nearer the lower limit: 10.025 - 9.9 = 0.125 < 10.2 - 10.025 = 0.175.
  EXPECT_NEAR(*d.cpk, 0.125 / (3 * 0.0645497224), 1e-8);
  // A value without a tolerance gets mean and sigma but no Cp.
  EXPECT_EQ(caps[1].name, "part.score");
  EXPECT_NEAR(caps[1].mean, 0.875, 1e-12);
  EXPECT_FALSE(caps[1].cp.has_value());
}

TEST(ProcessCapability, FailedMeasurementsAndSingleValues) {
  const std::vector<PartResult> parts{part(std::numeric_limits<double>::quiet_NaN(), 0.9),
                                      part(10.0, 0.8)};
  const auto caps = processCapability(parts);
  EXPECT_EQ(caps[0].count, 1u);  // the NaN is left out
  EXPECT_EQ(caps[0].sigma, 0.0);
  EXPECT_FALSE(caps[0].cp.has_value());  // no spread from one value
  EXPECT_TRUE(processCapability({}).empty());
}

}  // namespace
}  // namespace facet::service
