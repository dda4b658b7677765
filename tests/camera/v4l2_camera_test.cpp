// V4L2 backend against a scripted device behind the syscall seam: negotiation, the mmap buffer
// cycle, conversions, controls, sequence wrap-around, and a device that disappears.

#include <chrono>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/camera_factory.hpp"
#include "camera/v4l2_camera.hpp"
#include "scripted_v4l2_device.hpp"

namespace facet {
namespace {

using namespace std::chrono_literals;
using test::ScriptedV4l2Device;

cv::Mat randomImage(int rows, int cols, int type, int seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// Lays `image` out as the driver would: rows of `stride` bytes.
ScriptedV4l2Device::ScriptedFrame rawFrame(const cv::Mat& image, std::size_t stride) {
  ScriptedV4l2Device::ScriptedFrame f;
  f.bytes.assign(stride * image.rows, 0xEE);
  const std::size_t row_bytes = image.cols * image.elemSize();
  for (int y = 0; y < image.rows; ++y) std::memcpy(&f.bytes[y * stride], image.ptr(y), row_bytes);
  return f;
}

V4l2Settings settingsFor(const std::shared_ptr<ScriptedV4l2Device>& device, std::string format,
                         int width = 64, int height = 48) {
  V4l2Settings s;
  s.device = device->path;
  s.format = std::move(format);
  s.width = width;
  s.height = height;
  s.buffer_count = 3;
  s.reconnect_initial_ms = 1;
  s.reconnect_max_ms = 4;
  return s;
}

TEST(V4l2Camera, NegotiatesGreyAndDeliversPaddedRowsByteExact) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  device->row_padding = 16;
  V4l2Camera camera(settingsFor(device, "GREY"), device);
  camera.open();
  EXPECT_EQ(camera.fourcc(), "GREY");
  EXPECT_EQ(camera.width(), 64);
  EXPECT_EQ(camera.height(), 48);
  camera.start();
  EXPECT_TRUE(device->streaming());
  EXPECT_EQ(device->buffer_count(), 3u);
  EXPECT_EQ(device->queued(), 3u);
  EXPECT_EQ(device->live_mappings(), 3);

  std::vector<cv::Mat> images;
  for (int i = 0; i < 7; ++i) {  // more frames than buffers: every buffer must come back
    images.push_back(randomImage(48, 64, CV_8UC1, i));
    device->push(rawFrame(images.back(), 64 + 16));
  }
  std::vector<Frame> frames;
  for (int i = 0; i < 7; ++i) {
    GrabResult r = camera.grab(100ms);
    ASSERT_TRUE(r.ok()) << i << ": " << r.message;
    EXPECT_EQ(r.frame.format, PixelFormat::Mono8);
    EXPECT_EQ(r.frame.id, static_cast<std::uint64_t>(i));
    EXPECT_EQ(device->queued(), 3u) << "buffer queued again after each frame";
    frames.push_back(std::move(r.frame));
  }
  // Checked after the driver has refilled every buffer twice: a frame owns its pixels (the one
  // copy out of the mmap buffer), it never aliases driver memory.
  for (int i = 0; i < 7; ++i) EXPECT_TRUE(sameImage(frames[i].image, images[i])) << i;
  EXPECT_EQ(camera.grab(10ms).status, GrabStatus::Timeout);
  camera.close();
  EXPECT_EQ(device->live_mappings(), 0);
  EXPECT_FALSE(device->streaming());
}

TEST(V4l2Camera, PicksThePreferredOfferedFormatOrNamesWhatIsOffered) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  {
    V4l2Camera camera(settingsFor(device, ""), device);
    camera.open();
    EXPECT_EQ(camera.fourcc(), "GREY");  // GREY before YUYV before MJPG
  }
  device->formats = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_YUYV};
  {
    V4l2Camera camera(settingsFor(device, ""), device);
    camera.open();
    EXPECT_EQ(camera.fourcc(), "YUYV");
  }
  device->formats = {V4L2_PIX_FMT_MJPEG};
  V4l2Camera camera(settingsFor(device, "GREY"), device);
  try {
    camera.open();
    FAIL() << "open() should throw";
  } catch (const CameraError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/dev/video7"), std::string::npos) << what;
    EXPECT_NE(what.find("MJPG"), std::string::npos) << what;
  }
  EXPECT_THROW(V4l2Camera(settingsFor(device, "H264"), device), CameraError);
}

TEST(V4l2Camera, TakesTheSizeTheDriverSettlesOn) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  device->max_width = 32;
  device->max_height = 24;
  V4l2Camera camera(settingsFor(device, "GREY", 64, 48), device);
  camera.open();
  EXPECT_EQ(camera.width(), 32);
  EXPECT_EQ(camera.height(), 24);
  camera.start();
  const cv::Mat image = randomImage(24, 32, CV_8UC1, 3);
  device->push(rawFrame(image, 32));
  GrabResult r = camera.grab(100ms);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_TRUE(sameImage(r.frame.image, image));
}

TEST(V4l2Camera, ConvertsYuyvToColourOrGrey) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  const cv::Mat yuyv = randomImage(48, 64, CV_8UC2, 4);
  for (auto colour : {ColourConversion::Keep, ColourConversion::Mono}) {
    auto s = settingsFor(device, "YUYV");
    s.colour = colour;
    V4l2Camera camera(s, device);
    camera.open();
    camera.start();
    device->push(rawFrame(yuyv, 128));
    GrabResult r = camera.grab(100ms);
    ASSERT_TRUE(r.ok()) << r.message;
    cv::Mat expected;
    if (colour == ColourConversion::Mono) {
      cv::cvtColor(yuyv, expected, cv::COLOR_YUV2GRAY_YUYV);
      EXPECT_EQ(r.frame.format, PixelFormat::Mono8);
    } else {
      cv::cvtColor(yuyv, expected, cv::COLOR_YUV2BGR_YUYV);
      EXPECT_EQ(r.frame.format, PixelFormat::Bgr8);
    }
    EXPECT_TRUE(sameImage(r.frame.image, expected));
  }
}

TEST(V4l2Camera, DecodesMjpegAndCountsCorruptFrames) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  V4l2Camera camera(settingsFor(device, "MJPG"), device);
  camera.open();
  camera.start();
  cv::Mat picture = randomImage(48, 64, CV_8UC3, 5);
  cv::GaussianBlur(picture, picture, cv::Size(9, 9), 3);
  std::vector<std::uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", picture, jpeg));
  device->push({jpeg, false});
  device->push({std::vector<std::uint8_t>(jpeg.begin(), jpeg.begin() + 40), false});  // cut short
  device->push({jpeg, true});  // the driver flags an error
  device->push({jpeg, false});

  GrabResult good = camera.grab(100ms);
  ASSERT_TRUE(good.ok()) << good.message;
  EXPECT_EQ(good.frame.format, PixelFormat::Bgr8);
  EXPECT_TRUE(sameImage(good.frame.image, cv::imdecode(jpeg, cv::IMREAD_COLOR)));
  GrabResult cut = camera.grab(100ms);
  EXPECT_EQ(cut.status, GrabStatus::Incomplete);
  EXPECT_FALSE(cut.frame.complete);
  EXPECT_EQ(camera.grab(100ms).status, GrabStatus::Incomplete);
  EXPECT_TRUE(camera.grab(100ms).ok());
  const CameraHealth health = camera.health();
  EXPECT_EQ(health.incomplete_frames, 2u);
  EXPECT_EQ(health.frames, 2u);
  EXPECT_EQ(device->queued(), 3u);
}

TEST(V4l2Camera, ShortUncompressedBufferIsIncomplete) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  V4l2Camera camera(settingsFor(device, "GREY"), device);
  camera.open();
  camera.start();
  ScriptedV4l2Device::ScriptedFrame half;
  half.bytes.assign(64 * 24, 1);
  device->push(half);
  EXPECT_EQ(camera.grab(100ms).status, GrabStatus::Incomplete);
  EXPECT_EQ(camera.health().incomplete_frames, 1u);
}

TEST(V4l2Camera, UnwrapsThe32BitSequence) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  device->next_sequence = 0xFFFFFFFEu;
  V4l2Camera camera(settingsFor(device, "GREY"), device);
  camera.open();
  camera.start();
  const cv::Mat image = randomImage(48, 64, CV_8UC1, 6);
  std::vector<std::uint64_t> ids;
  for (int i = 0; i < 4; ++i) {
    device->push(rawFrame(image, 64));
    if (i == 2) ++device->next_sequence;  // sequence 0 is lost in the driver
    GrabResult r = camera.grab(100ms);
    ASSERT_TRUE(r.ok());
    ids.push_back(r.frame.id);
  }
  EXPECT_EQ(ids,
            (std::vector<std::uint64_t>{0xFFFFFFFEu, 0xFFFFFFFFu, 0x100000001u, 0x100000002u}));
  EXPECT_EQ(camera.health().lost_frames, 1u);
}

TEST(V4l2Camera, SetsExposureAndGainWhereTheDeviceHasThem) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  auto s = settingsFor(device, "GREY");
  s.exposure_us = 12000.0;
  s.gain = 7;
  {
    V4l2Camera camera(s, device);
    camera.open();
  }
  EXPECT_EQ(device->controls[V4L2_CID_EXPOSURE_AUTO], V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(device->controls[V4L2_CID_EXPOSURE_ABSOLUTE], 120);  // units of 100 us
  EXPECT_EQ(device->controls[V4L2_CID_GAIN], 7);

  device->controls.clear();  // a camera without these controls still opens
  V4l2Camera bare(s, device);
  EXPECT_NO_THROW(bare.open());
  EXPECT_TRUE(device->controls.empty());
}

TEST(V4l2Camera, MissingDeviceIsAClearError) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  device->disappear();
  V4l2Camera camera(settingsFor(device, "GREY"), device);
  try {
    camera.open();
    FAIL() << "open() should throw";
  } catch (const CameraError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/video7"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(camera.health().connected);
}

TEST(V4l2Camera, SurvivesTheDeviceDisappearingAndComingBack) {
  auto device = std::make_shared<ScriptedV4l2Device>();
  V4l2Camera camera(settingsFor(device, "GREY"), device);
  camera.open();
  camera.start();
  const cv::Mat image = randomImage(48, 64, CV_8UC1, 7);
  device->push(rawFrame(image, 64));
  ASSERT_TRUE(camera.grab(100ms).ok());

  device->disappear();  // unplugged: every call now fails with ENODEV
  EXPECT_EQ(camera.grab(100ms).status, GrabStatus::Disconnected);
  EXPECT_FALSE(camera.health().connected);
  EXPECT_EQ(device->live_mappings(), 0) << "buffers of a lost device are unmapped";
  EXPECT_EQ(camera.grab(20ms).status, GrabStatus::Disconnected);  // still gone

  device->reappear();
  device->push(rawFrame(image, 64));
  GrabResult r;
  for (int i = 0; i < 10 && !r.ok(); ++i) r = camera.grab(50ms);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_TRUE(sameImage(r.frame.image, image));
  EXPECT_EQ(r.frame.id, 1u) << "ids continue after a reconnect";
  const CameraHealth health = camera.health();
  EXPECT_TRUE(health.connected);
  EXPECT_EQ(health.reconnects, 1u);
  EXPECT_EQ(device->live_mappings(), 3);
  EXPECT_GE(device->open_count, 2);
}

TEST(V4l2Camera, FactoryBuildsAKernelBackedCameraThatNamesAMissingDevice) {
  CameraSettings settings;
  settings.backend = CameraBackend::V4l2;
  settings.v4l2.device = "/dev/facet-no-such-video-device";
  auto camera = makeCamera(settings);
  EXPECT_EQ(camera->name(), "v4l2:/dev/facet-no-such-video-device");
  try {
    camera->open();
    FAIL() << "open() should throw";
  } catch (const CameraError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/facet-no-such-video-device"), std::string::npos);
  }
}

}  // namespace
}  // namespace facet
