#pragma once
// Aravis' fake GigE Vision camera, started in this process on 127.0.0.1, serving known images:
// every frame is the region of a fixed random "sensor" picture that the camera was asked for,
// so a test can check the received bytes exactly.

#include <arv.h>
#include <opencv2/core.hpp>

#include <string>

namespace facet::test {

class FakeGigECamera {
 public:
  static constexpr const char* kAddress = "127.0.0.1";

  explicit FakeGigECamera(std::string serial = "FACET01") : serial_(std::move(serial)) {
    sensor8();  // build the pictures here, not on the camera's thread
    sensor16();
    sensorRgb();
    plugIn();
  }
  ~FakeGigECamera() { unplug(); }
  FakeGigECamera(const FakeGigECamera&) = delete;
  FakeGigECamera& operator=(const FakeGigECamera&) = delete;

  // Starts the camera (again): a power cycle is unplug() + plugIn().
  void plugIn() {
    if (camera_) return;
    camera_ = arv_gv_fake_camera_new(kAddress, serial_.c_str());
    if (camera_ && !arv_gv_fake_camera_is_running(camera_)) {
      g_object_unref(camera_);
      camera_ = nullptr;
    }
    if (!camera_) return;
    arv_fake_camera_set_fill_pattern(arv_gv_fake_camera_get_fake_camera(camera_), &fill, nullptr);
    g_object_set(camera_, "gvsp-lost-ratio", lost_ratio_, nullptr);
  }

  void unplug() {
    if (camera_) g_object_unref(camera_);
    camera_ = nullptr;
  }

  bool running() const { return camera_ != nullptr; }

  // Fraction of GVSP packets the camera drops on purpose (0..1).
  void setLostPacketRatio(double ratio) {
    lost_ratio_ = ratio;
    if (camera_) g_object_set(camera_, "gvsp-lost-ratio", ratio, nullptr);
  }

  // The picture on the fake sensor, as 8-bit, 16-bit and RGB (R first) images.
  static const cv::Mat& sensor8() { return sensor(CV_8UC1, 11); }
  static const cv::Mat& sensor16() { return sensor(CV_16UC1, 12); }
  static const cv::Mat& sensorRgb() { return sensor(CV_8UC3, 13); }

 private:
  static const cv::Mat& sensor(int type, int seed) {
    static cv::Mat images[3];
    cv::Mat& m = images[seed - 11];
    if (m.empty()) {
      m.create(ARV_FAKE_CAMERA_SENSOR_HEIGHT, ARV_FAKE_CAMERA_SENSOR_WIDTH, type);
      cv::RNG rng(static_cast<std::uint64_t>(seed));
      rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
    }
    return m;
  }

  // Runs on the fake camera's thread: copy the requested region of the sensor picture.
  static void fill(ArvBuffer* buffer, void*, guint32, guint32, ArvPixelFormat format) {
    const int width = arv_buffer_get_image_width(buffer);
    const int height = arv_buffer_get_image_height(buffer);
    const int x = arv_buffer_get_image_x(buffer);
    const int y = arv_buffer_get_image_y(buffer);
    void* data = const_cast<void*>(arv_buffer_get_data(buffer, nullptr));
    const cv::Mat* source = &sensor8();
    if (format == ARV_PIXEL_FORMAT_MONO_16) source = &sensor16();
    if (format == ARV_PIXEL_FORMAT_RGB_8_PACKED) source = &sensorRgb();
    if (!data || x + width > source->cols || y + height > source->rows) return;
    cv::Mat target(height, width, source->type(), data);
    (*source)(cv::Rect(x, y, width, height)).copyTo(target);
  }

  std::string serial_;
  double lost_ratio_ = 0.0;
  ArvGvFakeCamera* camera_ = nullptr;
};

}  // namespace facet::test
