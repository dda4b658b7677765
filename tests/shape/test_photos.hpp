#pragma once
// The photographs of tests/data/photos (their sources: tests/data/photos/README.md), for tests.

#include <string>

#include <opencv2/core.hpp>

namespace facet::testing {

// tests/data/photos/<file>, 8-bit grey; empty, with a test failure added, when it is missing.
cv::Mat testPhoto(const std::string& file);

}  // namespace facet::testing
