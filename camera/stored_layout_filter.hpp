#pragma once
// Which stored layouts a caller of an in-process image reader (png_file.hpp, tiff_file.hpp) can
// use, by the OpenCV type the pixels would have (CV_8UC3 for 8-bit RGB...). The readers ask it
// after the header, so that a file the caller would pass on to the module is not decoded first.

#include <functional>

namespace facet {

using StoredLayoutFilter = std::function<bool(int type)>;

}  // namespace facet
