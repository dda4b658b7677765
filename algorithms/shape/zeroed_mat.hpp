#pragma once
// Zeroed buffers that cost only the pages a search touches (internal to facet_shape).
//
// A search's per-image buffers are mostly never written: a direction field is computed only near
// the candidates, the top level's response maps only where the image has gradients. Clearing
// them all makes the process touch every page, and a page's first touch is a fault the system
// answers by mapping it (about 10 us on a virtual machine: a 4096x3000 image's buffers took
// 7000 of them, more than the whole warm search). calloc takes a fresh block from the system
// without writing it (large blocks usually are fresh: glibc maps them, though it raises that
// threshold as mapped blocks are freed), and the system maps each page zeroed on its first
// touch; a block calloc recycles it clears itself. Either way the buffer reads as zeros.

#include <opencv2/core.hpp>

namespace facet::shape_detail {

// A continuous cv::Mat of `size` and `type`, all zero, whose pages are touched only when used.
cv::Mat zeroedMat(cv::Size size, int type);

}  // namespace facet::shape_detail
