// A replay folder full of bad files, as an operator might copy to a station: truncated,
// zero-byte, wrong-extension and huge-header images. Each is refused with a message naming it,
// none crashes the replay, the good frames around them still arrive byte-exact, and memory stays
// bounded even when headers announce gigabytes of pixels.

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "camera/image_codecs.hpp"
#include "camera/replay_camera.hpp"
#include "tests/hardening/bad_image_files.hpp"
#include "tests/support/process/peak_resident_memory.hpp"

namespace facet {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

class Folder {
 public:
  Folder() {
    std::random_device rd;
    path_ = fs::temp_directory_path() / ("facet_replay_faults_" + std::to_string(rd()));
    fs::create_directories(path_);
  }
  ~Folder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  Folder(const Folder&) = delete;
  Folder& operator=(const Folder&) = delete;
  const fs::path& path() const { return path_; }
  void write(const std::string& name, const std::string& bytes) const {
    std::ofstream(path_ / name, std::ios::binary) << bytes;
  }

 private:
  fs::path path_;
};

TEST(ReplayFaults, EveryBadFileIsRefusedWithItsNameAndGoodFramesStillArrive) {
  Folder folder;
  cv::Mat good(48, 64, CV_8UC1);
  cv::randu(good, 0, 256);
  const std::string png = test::encodeImage(".png", good);
  folder.write("part_00_good.png", png);
  folder.write("part_01_truncated.png", png.substr(0, png.size() / 2));
  folder.write("part_02_zero_bytes.png", "");
  folder.write("part_03_text_named_png.png", "serial;verdict\n4711;good\n");
  folder.write("part_04_huge_30000x30000.png", test::pngHeaderOnly(30000, 30000, 8, 0));
  folder.write("part_05_huge_pgm.pgm", "P5\n30000 30000\n255\n\x01\x02");
  folder.write("part_06_tiff_named_bmp.bmp", "II*\0garbage");
  folder.write("part_07_good.png", png);
  const std::vector<std::string> bad = {
      "part_01_truncated.png",        "part_02_zero_bytes.png", "part_03_text_named_png.png",
      "part_04_huge_30000x30000.png", "part_05_huge_pgm.pgm",   "part_06_tiff_named_bmp.bmp"};

  ReplaySettings settings;
  settings.folder = folder.path();
  ReplayCamera camera(settings);
  camera.open();
  camera.start();

  GrabResult first = camera.grab(1s);
  ASSERT_TRUE(first.ok()) << first.message;
  EXPECT_NE(first.frame.source.find("part_00_good.png"), std::string::npos);
  EXPECT_EQ(camera.health().skipped_files, 0u);

  // Every bad file is skipped on the way to the next good one; the error of the last one is
  // kept, and each was logged. Check them one at a time to see every message.
  GrabResult second = camera.grab(1s);
  ASSERT_TRUE(second.ok()) << second.message;
  EXPECT_NE(second.frame.source.find("part_07_good.png"), std::string::npos);
  EXPECT_EQ(cv::norm(second.frame.image, good, cv::NORM_INF), 0.0);
  EXPECT_EQ(second.frame.id, 1u) << "refused files take no frame number";
  EXPECT_EQ(camera.health().skipped_files, bad.size());
  EXPECT_EQ(camera.grab(1s).status, GrabStatus::EndOfStream);

  for (const auto& name : bad) {
    Folder single;
    fs::copy_file(folder.path() / name, single.path() / name);
    ReplaySettings one;
    one.folder = single.path();
    ReplayCamera c(one);
    c.open();
    c.start();
    const GrabResult r = c.grab(1s);
    EXPECT_EQ(r.status, GrabStatus::EndOfStream) << name;
    EXPECT_FALSE(r.frame.image.data) << name;
    EXPECT_EQ(c.health().skipped_files, 1u) << name;
    EXPECT_NE(c.health().last_error.find(name), std::string::npos)
        << name << ": " << c.health().last_error;
  }
}

TEST(ReplayFaults, HugeHeadersUnderThePixelLimitKeepMemoryBounded) {
  // Headers that pass the pixel limit (2^28 by default) but whose data is missing: the reader
  // may reserve the announced size, but must not fill it, and must give it back.
  Folder folder;
  folder.write("a_16000x16000_mono8.png", test::pngHeaderOnly(16000, 16000, 8, 0));
  folder.write("b_16000x16000_rgb16.png", test::pngHeaderOnly(16000, 16000, 16, 2));
  folder.write("c_12000x12000.pgm", "P5\n12000 12000\n65535\n\x01\x02\x03\x04");
  cv::Mat good(32, 32, CV_8UC1, cv::Scalar(7));
  folder.write("d_good.png", test::encodeImage(".png", good));

  ReplaySettings settings;
  settings.folder = folder.path();
  settings.loop = true;
  ReplayCamera camera(settings);
  camera.open();
  camera.start();
  // The codec module and its libraries, loaded on first use, are not what is measured (under
  // AddressSanitizer they alone add tens of MB): load them before the baseline.
  ASSERT_EQ(imageCodecsProblem(), "");
  const std::uint64_t before = test::ownPeakResidentBytes();
  for (int pass = 0; pass < 5; ++pass) {
    GrabResult r = camera.grab(1s);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_NE(r.frame.source.find("d_good.png"), std::string::npos);
  }
  const std::uint64_t growth = test::ownPeakResidentBytes() - before;
  std::printf("peak RSS grew by %llu MB\n", static_cast<unsigned long long>(growth >> 20));
  EXPECT_EQ(camera.health().skipped_files, 15u);
  EXPECT_NE(camera.health().last_error.find("c_12000x12000.pgm"), std::string::npos)
      << camera.health().last_error;
  // 16000 x 16000 RGB16 would be 1.5 GB if the buffer were touched.
  EXPECT_LT(growth, std::uint64_t{200} << 20) << "peak RSS grew by " << (growth >> 20) << " MB";
}

}  // namespace
}  // namespace facet
