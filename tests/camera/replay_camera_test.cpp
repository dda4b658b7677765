// Replay backend: file order, formats, colour conversion, pacing, triggers, sidecar metadata and
// bad files, all on real files written into a scratch folder.

#include <chrono>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/camera_factory.hpp"
#include "camera/image_file_list.hpp"
#include "camera/replay_camera.hpp"
#include "temp_folder.hpp"

// Asan builds: OpenImageIO 2.4 leaks its error string (31 bytes) when libpng aborts a truncated
// PNG by longjmp; that is the library's, not ours, and would otherwise fail the leak check.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:OpenImageIO_v2_4::ImageInput::geterror\n";
}

namespace facet {
namespace {

using namespace std::chrono_literals;
using test::TempFolder;

cv::Mat randomImage(int rows, int cols, int type, int seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

ReplaySettings replayOf(const TempFolder& folder) {
  ReplaySettings s;
  s.folder = folder.path();
  return s;
}

std::vector<GrabResult> grabAll(Camera& camera, int max_frames = 100) {
  std::vector<GrabResult> results;
  for (int i = 0; i < max_frames; ++i) {
    GrabResult r = camera.grab(1s);
    const bool done = r.status == GrabStatus::EndOfStream;
    results.push_back(std::move(r));
    if (done) break;
  }
  return results;
}

TEST(NaturalOrder, NumbersCompareByValue) {
  EXPECT_TRUE(naturalLess("img2.png", "img10.png"));
  EXPECT_FALSE(naturalLess("img10.png", "img2.png"));
  EXPECT_TRUE(naturalLess("a9b", "a10a"));
  EXPECT_TRUE(naturalLess("part1_3", "part1_20"));
  EXPECT_TRUE(naturalLess("x", "x1"));
  EXPECT_FALSE(naturalLess("img7", "img7"));
  EXPECT_TRUE(naturalLess("img7", "img007"));  // equal value: fewer zeros first, still strict
  EXPECT_TRUE(naturalLess("img99999999999999999999999", "img100000000000000000000000"));
}

TEST(NaturalOrder, GlobMatches) {
  EXPECT_TRUE(globMatch("*.png", "a.png"));
  EXPECT_FALSE(globMatch("*.png", "a.png.json"));
  EXPECT_TRUE(globMatch("part_??.tif", "part_07.tif"));
  EXPECT_FALSE(globMatch("part_??.tif", "part_7.tif"));
  EXPECT_TRUE(globMatch("*a*b*", "xxaYYbzz"));
  EXPECT_FALSE(globMatch("*a*b", "xxaYYbzz"));
}

TEST(ReplayCamera, PlaysFilesInNaturalOrderAndEnds) {
  TempFolder folder;
  for (int i : {10, 2, 1}) {
    cv::Mat m(8, 8, CV_8UC1, cv::Scalar(i));
    ASSERT_TRUE(cv::imwrite((folder / ("img" + std::to_string(i) + ".png")).string(), m));
  }
  folder.write("notes.txt", "not an image");
  auto camera = makeCamera(CameraSettings{CameraBackend::Replay, replayOf(folder), {}, {}, {}});
  camera->open();
  camera->start();
  auto results = grabAll(*camera);
  ASSERT_EQ(results.size(), 4u);
  const int expected[] = {1, 2, 10};
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(results[i].ok()) << results[i].message;
    EXPECT_EQ(results[i].frame.image.at<std::uint8_t>(0, 0), expected[i]);
    EXPECT_EQ(results[i].frame.id, static_cast<std::uint64_t>(i));
    EXPECT_EQ(results[i].frame.format, PixelFormat::Mono8);
    EXPECT_TRUE(results[i].frame.complete);
  }
  EXPECT_EQ(results[3].status, GrabStatus::EndOfStream);
  EXPECT_EQ(camera->health().frames, 3u);
}

TEST(ReplayCamera, GlobSelectsAndLoopRepeats) {
  TempFolder folder;
  for (int i = 1; i <= 3; ++i) {
    cv::Mat m(4, 4, CV_8UC1, cv::Scalar(i));
    cv::imwrite((folder / ("good" + std::to_string(i) + ".png")).string(), m);
    cv::imwrite((folder / ("other" + std::to_string(i) + ".png")).string(), m);
  }
  auto settings = replayOf(folder);
  settings.glob = "good*.png";
  settings.loop = true;
  ReplayCamera camera(settings);
  camera.open();
  ASSERT_EQ(camera.files().size(), 3u);
  camera.start();
  for (int i = 0; i < 7; ++i) {
    GrabResult r = camera.grab(1s);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_EQ(r.frame.image.at<std::uint8_t>(0, 0), i % 3 + 1);
    EXPECT_EQ(r.frame.id, static_cast<std::uint64_t>(i));
    EXPECT_NE(r.frame.source.find("good"), std::string::npos);
  }
}

TEST(ReplayCamera, ReadsEveryFormatByteExact) {
  TempFolder folder;
  const cv::Mat grey8 = randomImage(37, 53, CV_8UC1, 1);
  const cv::Mat grey16 = randomImage(37, 53, CV_16UC1, 2);
  const cv::Mat bgr8 = randomImage(37, 53, CV_8UC3, 3);
  struct Case {
    std::string name;
    cv::Mat image;
    PixelFormat format;
  };
  const std::vector<Case> cases = {
      {"a01.png", grey8, PixelFormat::Mono8},   {"a02.png", grey16, PixelFormat::Mono16},
      {"a03.png", bgr8, PixelFormat::Bgr8},     {"a04.tif", grey8, PixelFormat::Mono8},
      {"a05.tif", grey16, PixelFormat::Mono16}, {"a06.tif", bgr8, PixelFormat::Bgr8},
      {"a07.bmp", grey8, PixelFormat::Mono8},   {"a08.bmp", bgr8, PixelFormat::Bgr8},
      {"a09.pgm", grey8, PixelFormat::Mono8},   {"a10.pgm", grey16, PixelFormat::Mono16},
      {"a11.ppm", bgr8, PixelFormat::Bgr8},
  };
  for (const auto& c : cases) ASSERT_TRUE(cv::imwrite((folder / c.name).string(), c.image));
  // JPEG is lossy: compared with a tolerance below.
  ASSERT_TRUE(cv::imwrite((folder / "a12.jpg").string(), cv::Mat(37, 53, CV_8UC1, 90)));

  ReplayCamera camera(replayOf(folder));
  camera.open();
  camera.start();
  for (const auto& c : cases) {
    GrabResult r = camera.grab(1s);
    ASSERT_TRUE(r.ok()) << c.name << ": " << r.message;
    EXPECT_EQ(r.frame.format, c.format) << c.name;
    EXPECT_TRUE(sameImage(r.frame.image, c.image)) << c.name;
  }
  GrabResult jpeg = camera.grab(1s);
  ASSERT_TRUE(jpeg.ok()) << jpeg.message;
  EXPECT_EQ(jpeg.frame.format, PixelFormat::Mono8);
  EXPECT_LE(cv::norm(jpeg.frame.image, cv::Mat(37, 53, CV_8UC1, 90), cv::NORM_INF), 2.0);
  EXPECT_EQ(camera.grab(1s).status, GrabStatus::EndOfStream);
}

TEST(ReplayCamera, ConvertsColourAsAsked) {
  TempFolder folder;
  const cv::Mat bgr = randomImage(16, 16, CV_8UC3, 4);
  const cv::Mat grey = randomImage(16, 16, CV_8UC1, 5);
  cv::imwrite((folder / "1.png").string(), bgr);
  cv::imwrite((folder / "2.png").string(), grey);

  auto settings = replayOf(folder);
  settings.colour = ColourConversion::Mono;
  ReplayCamera mono(settings);
  mono.open();
  mono.start();
  GrabResult a = mono.grab(1s);
  ASSERT_TRUE(a.ok());
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(a.frame.format, PixelFormat::Mono8);
  EXPECT_TRUE(sameImage(a.frame.image, expected));

  settings.colour = ColourConversion::Colour;
  ReplayCamera colour(settings);
  colour.open();
  colour.start();
  colour.grab(1s);
  GrabResult b = colour.grab(1s);
  ASSERT_TRUE(b.ok());
  cv::cvtColor(grey, expected, cv::COLOR_GRAY2BGR);
  EXPECT_EQ(b.frame.format, PixelFormat::Bgr8);
  EXPECT_TRUE(sameImage(b.frame.image, expected));
}

TEST(ReplayCamera, SkipsBrokenFilesAndCountsThem) {
  TempFolder folder;
  const cv::Mat good = randomImage(64, 64, CV_8UC1, 6);
  cv::imwrite((folder / "f1.png").string(), good);
  // Truncated PNG: the header is intact, the pixel data is cut short.
  std::vector<std::uint8_t> png;
  cv::imencode(".png", randomImage(64, 64, CV_8UC1, 7), png);
  folder.write("f2.png", std::string(png.begin(), png.begin() + png.size() / 2));
  folder.write("f3.png", "this is not a PNG at all");
  // A PGM header announcing 10^10 pixels: must be refused before allocating anything.
  folder.write("f4.pgm", "P5\n100000 100000\n255\n\x01\x02\x03");
  folder.write("f5.tif", "II*\0garbage");
  // Truncated raw PGM: a valid header, half the pixel bytes.
  folder.write("f5b.pgm", "P5\n64 64\n255\n" + std::string(64 * 32, '\x07'));
  cv::imwrite((folder / "f6.png").string(), good);

  ReplayCamera camera(replayOf(folder));
  camera.open();
  camera.start();
  GrabResult first = camera.grab(1s);
  ASSERT_TRUE(first.ok()) << first.message;
  EXPECT_NE(first.frame.source.find("f1.png"), std::string::npos);
  GrabResult second = camera.grab(1s);
  ASSERT_TRUE(second.ok()) << second.message;
  EXPECT_NE(second.frame.source.find("f6.png"), std::string::npos);
  EXPECT_TRUE(sameImage(second.frame.image, good));
  EXPECT_EQ(second.frame.id, 1u);
  const CameraHealth health = camera.health();
  EXPECT_EQ(health.skipped_files, 5u);
  EXPECT_EQ(health.frames, 2u);
  EXPECT_NE(health.last_error.find("f5b.pgm"), std::string::npos) << health.last_error;
  EXPECT_EQ(camera.grab(1s).status, GrabStatus::EndOfStream);
}

TEST(ReplayCamera, RefusesOversizedHeaderWithItsName) {
  TempFolder folder;
  cv::imwrite((folder / "big.png").string(), cv::Mat(100, 100, CV_8UC1, 1));
  auto settings = replayOf(folder);
  settings.max_pixels = 100 * 99;
  ReplayCamera camera(settings);
  camera.open();
  camera.start();
  GrabResult r = camera.grab(1s);
  EXPECT_EQ(r.status, GrabStatus::EndOfStream);
  EXPECT_EQ(camera.health().skipped_files, 1u);
  EXPECT_NE(camera.health().last_error.find("big.png"), std::string::npos);
  EXPECT_NE(camera.health().last_error.find("exceeds"), std::string::npos);
}

TEST(ReplayCamera, LoopOverOnlyBrokenFilesEndsWithError) {
  TempFolder folder;
  folder.write("a.png", "junk");
  folder.write("b.png", "junk");
  auto settings = replayOf(folder);
  settings.loop = true;
  ReplayCamera camera(settings);
  camera.open();
  camera.start();
  EXPECT_EQ(camera.grab(1s).status, GrabStatus::Error);
  EXPECT_EQ(camera.health().skipped_files, 2u);
}

TEST(ReplayCamera, ReportUnreadableReturnsEachBadFileOnceAsAnErrorNamingIt) {
  TempFolder folder;
  const cv::Mat good = randomImage(16, 16, CV_8UC1, 3);
  cv::imwrite((folder / "a1.png").string(), good);
  folder.write("a2.png", "junk");
  folder.write("a2.png.json", R"({"serial": "S-2", "expected_verdict": "pass"})");
  cv::imwrite((folder / "a3.png").string(), good);
  auto settings = replayOf(folder);
  settings.loop = true;
  settings.report_unreadable = true;
  ReplayCamera camera(settings);
  camera.open();
  camera.start();
  const GrabResult first = camera.grab(1s);
  ASSERT_TRUE(first.ok()) << first.message;
  const GrabResult refused = camera.grab(1s);
  ASSERT_EQ(refused.status, GrabStatus::Error);
  EXPECT_EQ(refused.frame.source, (folder / "a2.png").string());
  EXPECT_NE(refused.message.find("a2.png"), std::string::npos) << refused.message;
  EXPECT_TRUE(refused.frame.image.empty());
  EXPECT_EQ(refused.frame.metadata.at("serial"), "S-2");
  const GrabResult third = camera.grab(1s);
  ASSERT_TRUE(third.ok()) << third.message;
  EXPECT_EQ(third.frame.id, 1u) << "a refused file takes no frame number";
  // The second pass skips it: a1, a3, a1.
  for (const char* name : {"a1.png", "a3.png", "a1.png"}) {
    const GrabResult r = camera.grab(1s);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_NE(r.frame.source.find(name), std::string::npos) << r.frame.source;
  }
  EXPECT_EQ(camera.health().skipped_files, 2u);
}

TEST(ReplayCamera, MissingOrEmptyFolderIsAnErrorNamingIt) {
  TempFolder folder;
  auto settings = replayOf(folder);
  settings.folder = folder / "does_not_exist";
  ReplayCamera missing(settings);
  try {
    missing.open();
    FAIL() << "open() should throw";
  } catch (const CameraError& e) {
    EXPECT_NE(std::string(e.what()).find("does_not_exist"), std::string::npos);
  }
  ReplayCamera empty(replayOf(folder));
  EXPECT_THROW(empty.open(), CameraError);
  EXPECT_THROW(ReplayCamera(ReplaySettings{}), CameraError);
}

TEST(ReplayCamera, SoftwareTriggerGivesOneFramePerTrigger) {
  TempFolder folder;
  for (int i = 0; i < 3; ++i)
    cv::imwrite((folder / ("t" + std::to_string(i) + ".png")).string(),
                cv::Mat(4, 4, CV_8UC1, cv::Scalar(i)));
  auto settings = replayOf(folder);
  settings.trigger = TriggerMode::Software;
  ReplayCamera camera(settings);
  camera.open();
  EXPECT_EQ(camera.grab(10ms).status, GrabStatus::NotStarted);
  camera.start();
  EXPECT_EQ(camera.grab(20ms).status, GrabStatus::Timeout);
  camera.softwareTrigger();
  camera.softwareTrigger();
  EXPECT_TRUE(camera.grab(1s).ok());
  EXPECT_TRUE(camera.grab(1s).ok());
  EXPECT_EQ(camera.grab(20ms).status, GrabStatus::Timeout);
  // A trigger from another thread wakes a waiting grab.
  std::thread trigger([&] {
    std::this_thread::sleep_for(30ms);
    camera.softwareTrigger();
  });
  GrabResult r = camera.grab(5s);
  trigger.join();
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.frame.image.at<std::uint8_t>(0, 0), 2);
  EXPECT_EQ(camera.health().timeouts, 2u);
}

TEST(ReplayCamera, FrameRatePacesFreeRun) {
  TempFolder folder;
  cv::imwrite((folder / "a.png").string(), cv::Mat(4, 4, CV_8UC1, 1));
  auto settings = replayOf(folder);
  settings.loop = true;
  settings.fps = 50.0;
  ReplayCamera camera(settings);
  camera.open();
  camera.start();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(camera.grab(1s).ok());
  // Six frames at 50 fps span at least five periods (a lower bound only: no timing target).
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 5 * 20ms - 2ms);
  // A timeout shorter than the period gives Timeout, not a frame (a long period, so that a
  // slow decode cannot make the next frame due already).
  settings.fps = 2.0;
  ReplayCamera slow(settings);
  slow.open();
  slow.start();
  ASSERT_TRUE(slow.grab(1s).ok());
  EXPECT_EQ(slow.grab(1ms).status, GrabStatus::Timeout);
  EXPECT_EQ(slow.health().timeouts, 1u);
}

TEST(ReplayCamera, ReadAheadIsBoundedAndBadFilesCountWhenReached) {
  TempFolder folder;
  for (int i = 0; i < 5; ++i)
    cv::imwrite((folder / ("p" + std::to_string(i) + ".png")).string(),
                cv::Mat(4, 4, CV_8UC1, cv::Scalar(i)));
  auto settings = replayOf(folder);
  settings.trigger = TriggerMode::Software;
  settings.prefetch = 2;
  ReplayCamera camera(settings);
  camera.open();
  camera.start();
  // Time for the read-ahead to fill up (with p0 and p1), then break the files after those: with
  // at most two files read ahead, p2 and p3 are read only once p0 has been delivered.
  std::this_thread::sleep_for(300ms);
  folder.write("p2.png", "broken after start");
  folder.write("p3.png", "broken after start");
  for (int expected : {0, 1}) {
    camera.softwareTrigger();
    GrabResult r = camera.grab(5s);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_EQ(r.frame.image.at<std::uint8_t>(0, 0), expected);
    EXPECT_EQ(camera.health().skipped_files, 0u) << "a bad file counts when grab reaches it";
  }
  camera.softwareTrigger();
  GrabResult r = camera.grab(5s);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.frame.image.at<std::uint8_t>(0, 0), 4);
  EXPECT_EQ(r.frame.id, 2u);
  EXPECT_EQ(camera.health().skipped_files, 2u);
  EXPECT_NE(camera.health().last_error.find("p3.png"), std::string::npos)
      << camera.health().last_error;
  EXPECT_EQ(camera.grab(20ms).status, GrabStatus::Timeout);  // still one frame per trigger
  camera.softwareTrigger();
  EXPECT_EQ(camera.grab(5s).status, GrabStatus::EndOfStream);
  camera.softwareTrigger();
  EXPECT_EQ(camera.grab(5s).status, GrabStatus::EndOfStream);
}

TEST(ReplayCamera, ReadAheadDeliversWhatReadingOnGrabDelivers) {
  TempFolder folder;
  for (int i = 0; i < 4; ++i)
    cv::imwrite((folder / ("q" + std::to_string(i) + ".png")).string(),
                randomImage(24, 32, CV_8UC1, 10 + i));
  folder.write("q2.png", "junk");
  auto settings = replayOf(folder);
  settings.loop = true;
  settings.prefetch = 0;
  ReplayCamera direct(settings);
  settings.prefetch = 3;
  ReplayCamera ahead(settings);
  for (ReplayCamera* c : {&direct, &ahead}) {
    c->open();
    c->start();
  }
  for (int i = 0; i < 8; ++i) {
    const GrabResult a = direct.grab(1s), b = ahead.grab(1s);
    ASSERT_TRUE(a.ok() && b.ok()) << a.message << " / " << b.message;
    EXPECT_EQ(a.frame.source, b.frame.source);
    EXPECT_EQ(a.frame.id, b.frame.id);
    EXPECT_TRUE(sameImage(a.frame.image, b.frame.image));
  }
  EXPECT_EQ(direct.health().skipped_files, ahead.health().skipped_files);
  EXPECT_EQ(ahead.health().frames, 8u);
}

TEST(ReplayCamera, RestartResumesAtTheFirstFileNotDelivered) {
  TempFolder folder;
  const std::vector<std::string> names = {"r0.png", "r1.png", "r2.png", "r3.png"};
  for (int i = 0; i < 4; ++i)
    cv::imwrite((folder / names[static_cast<std::size_t>(i)]).string(),
                cv::Mat(4, 4, CV_8UC1, cv::Scalar(i)));
  auto settings = replayOf(folder);
  settings.prefetch = 3;
  ReplayCamera camera(settings);
  camera.open();
  camera.start();
  ASSERT_EQ(camera.grab(1s).frame.image.at<std::uint8_t>(0, 0), 0);
  std::this_thread::sleep_for(50ms);  // r1..r3 read ahead, then dropped by stop()
  camera.stop();
  EXPECT_EQ(camera.grab(10ms).status, GrabStatus::NotStarted);
  camera.start();
  for (int expected : {1, 2, 3}) {
    GrabResult r = camera.grab(1s);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_EQ(r.frame.image.at<std::uint8_t>(0, 0), expected);
    EXPECT_EQ(r.frame.id, static_cast<std::uint64_t>(expected));
  }
  EXPECT_EQ(camera.grab(1s).status, GrabStatus::EndOfStream);
}

TEST(ReplayCamera, SidecarMetadataFlowsIntoFrames) {
  TempFolder folder;
  for (const char* name : {"p1.png", "p2.png", "p3.png"})
    cv::imwrite((folder / name).string(), cv::Mat(4, 4, CV_8UC1, 1));
  folder.write("sidecar.json", R"({"defaults": {"expected_verdict": "pass", "line": 3},
    "images": {"p2.png": {"serial": "SN-2", "expected_verdict": "fail"}}})");
  folder.write("p3.png.json", R"({"serial": "SN-3", "dims": {"w": 1.5}})");
  ReplayCamera camera(replayOf(folder));
  camera.open();
  camera.start();
  const Frame f1 = camera.grab(1s).frame;
  const Frame f2 = camera.grab(1s).frame;
  const Frame f3 = camera.grab(1s).frame;
  EXPECT_EQ(f1.metadata.at("expected_verdict"), "pass");
  EXPECT_EQ(f1.metadata.at("line"), "3");
  EXPECT_EQ(f1.metadata.count("serial"), 0u);
  EXPECT_EQ(f2.metadata.at("serial"), "SN-2");
  EXPECT_EQ(f2.metadata.at("expected_verdict"), "fail");
  EXPECT_EQ(f3.metadata.at("serial"), "SN-3");
  EXPECT_EQ(f3.metadata.at("expected_verdict"), "pass");
  EXPECT_EQ(f3.metadata.at("dims"), R"({"w":1.5})");
}

TEST(ReplayCamera, MalformedSidecarsAreReportedWithTheirFileName) {
  TempFolder folder;
  cv::imwrite((folder / "p1.png").string(), cv::Mat(4, 4, CV_8UC1, 1));
  folder.write("p1.png.json", "{\"serial\": ");
  ReplayCamera camera(replayOf(folder));
  camera.open();
  camera.start();
  GrabResult r = camera.grab(1s);
  ASSERT_TRUE(r.ok()) << r.message;  // the image is still good; its sidecar is ignored
  EXPECT_EQ(r.frame.metadata.count("serial"), 0u);
  EXPECT_NE(camera.health().last_error.find("p1.png.json"), std::string::npos);

  folder.write("sidecar.json", "{\"defaults\": [1, 2]}");
  ReplayCamera broken(replayOf(folder));
  try {
    broken.open();
    FAIL() << "open() should throw";
  } catch (const CameraError& e) {
    EXPECT_NE(std::string(e.what()).find("sidecar.json"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace facet
