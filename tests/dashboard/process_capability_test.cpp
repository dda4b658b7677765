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

// A position error (true position) is bounded at 0: the band [0, 0.1] is one-sided. A good
// process close to 0 is capable by its upper limit (Cpu), not "not capable" against the lower
// limit 0 it can never cross.
TEST(ProcessCapability, OneSidedIndexWhereALimitIsANaturalBound) {
  // 0.01, 0.02, 0.03, 0.02, 0.02: mean 0.02, sample sigma sqrt(0.0002 / 4) = 0.00707107.
  std::vector<PartResult> parts;
  for (double v : {0.01, 0.02, 0.03, 0.02, 0.02}) {
    PartResult p;
    p.measurements.push_back({.name = "small_bore.position",
                              .value = v,
                              .unit = "mm",
                              .nominal = 0.0,
                              .tolMinus = 0.0,
                              .tolPlus = 0.1,
                              .checked = true});
    p.measurements.push_back({.name = "part.score",
                              .value = 0.9 + v,
                              .unit = "score",
                              .nominal = 1.0,
                              .tolMinus = 0.2,
                              .tolPlus = 0.0,
                              .checked = true});
    parts.push_back(p);
  }
  const auto caps = processCapability(parts);
  ASSERT_EQ(caps.size(), 2u);
  const Capability& position = caps[0];
  const double sigma = std::sqrt(0.0002 / 4);
  EXPECT_NEAR(position.sigma, sigma, 1e-12);
  EXPECT_EQ(position.index, "Cpu");
  ASSERT_TRUE(position.cpk.has_value());
  EXPECT_NEAR(*position.cpk, (0.1 - 0.02) / (3 * sigma), 1e-9);  // 3.77, not 0.94
  EXPECT_FALSE(position.cp.has_value()) << "no Cp for a one-sided band";
  // A score cannot exceed 1: its upper limit 1 is a natural bound, the index is Cpl.
  const Capability& score = caps[1];
  EXPECT_EQ(score.index, "Cpl");
  ASSERT_TRUE(score.cpk.has_value());
  EXPECT_NEAR(*score.cpk, (0.92 - 0.8) / (3 * sigma), 1e-9);
}

TEST(ProcessCapability, TwoRealLimitsKeepCpk) {
  const auto caps = processCapability({part(9.95, 0.9), part(10.05, 0.9)});
  EXPECT_EQ(caps[0].index, "Cpk");
  EXPECT_TRUE(caps[0].cp.has_value());
  EXPECT_TRUE(naturalBounds("bore.diameter", "mm").lower.has_value());
  EXPECT_FALSE(naturalBounds("part.x", "mm").lower.has_value());
}

}  // namespace
}  // namespace facet::service
