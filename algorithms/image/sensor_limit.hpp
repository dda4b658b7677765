#pragma once
// The largest grey value a sensor gives, on the 8-bit scale the measurements work in: a pixel
// there, or at 0, is at the sensor's limit, and what it saw may have been brighter (or darker).

#include <opencv2/core.hpp>

namespace facet {

// 255 for an 8-bit image; 65535 / 256 for a 16-bit one (its values read divided by 256).
inline double sensorLimit(int depth) {
  return depth == CV_16U ? 65535.0 / 256.0 : 255.0;
}

}  // namespace facet
