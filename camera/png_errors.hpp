#pragma once
// How facet's libpng reader and writer take libpng's errors and warnings. libpng reports an error
// by calling the error function, which must not return: it jumps back to the last setjmp on the
// png struct, and the function that set it returns failure. The functions that set it hold
// nothing with a destructor, so a jump skips no C++ cleanup. Warnings are dropped: the reader
// leaves a file it cannot take whole to the image-codec module, which words the problem.

#include <png.h>

namespace facet::png_errors {

[[noreturn]] inline void jumpBack(png_structp png, png_const_charp) {
  png_longjmp(png, 1);
}

inline void ignore(png_structp, png_const_charp) {}

}  // namespace facet::png_errors
