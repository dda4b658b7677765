#include "algorithms/shape/zeroed_mat.hpp"

#include <cstdlib>

namespace facet::shape_detail {
namespace {

// cv::Mat's storage from calloc (OpenCV's own allocator mallocs, and Mat::zeros then writes every
// byte). Only Mat::create's buffers: a Mat over the caller's data never reaches it.
class ZeroedAllocator : public cv::MatAllocator {
 public:
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data, size_t* step,
                         cv::AccessFlag /*flags*/, cv::UMatUsageFlags /*usage*/) const override {
    CV_Assert(data == nullptr);
    size_t bytes = CV_ELEM_SIZE(type);
    for (int i = dims - 1; i >= 0; --i) {
      if (step) step[i] = bytes;
      bytes *= static_cast<size_t>(sizes[i]);
    }
    void* zeroed = std::calloc(bytes, 1);
    if (!zeroed) CV_Error(cv::Error::StsNoMem, "out of memory for a zeroed buffer");
    auto* u = new cv::UMatData(this);
    u->data = u->origdata = static_cast<uchar*>(zeroed);
    u->size = bytes;
    return u;
  }
  bool allocate(cv::UMatData* u, cv::AccessFlag /*flags*/,
                cv::UMatUsageFlags /*usage*/) const override {
    return u != nullptr;
  }
  void deallocate(cv::UMatData* u) const override {
    if (!u) return;
    std::free(u->origdata);
    delete u;
  }
};

}  // namespace

cv::Mat zeroedMat(cv::Size size, int type) {
  // Never destroyed: threads' kept buffers may outlive the statics at exit and still free.
  static ZeroedAllocator* const allocator = new ZeroedAllocator;
  cv::Mat m;
  m.allocator = allocator;
  m.create(size, type);
  return m;
}

}  // namespace facet::shape_detail
