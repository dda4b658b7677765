// bench_camera: frames per second and CPU time per frame
//   - through the replay backend (1280x1024 Mono8, PNG and raw PGM), beside cv::imread of the
//     same files in the same run;
//   - through the Aravis backend from the fake GigE camera on 127.0.0.1, beside a bare Aravis
//     pop/push loop (no conversion, no copy) in the same run.
// --smoke: few frames, short streams (< 20 s), same table.

#include <OpenImageIO/imageio.h>
#include <arv.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/aravis_camera.hpp"
#include "camera/replay_camera.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Measure {
  std::string name;
  int frames = 0;
  int incomplete = 0;
  double wall_s = 0.0;
  double cpu_s = 0.0;
  double fps() const { return frames > 0 ? frames / wall_s : 0.0; }
  double cpuMsPerFrame() const { return frames > 0 ? 1e3 * cpu_s / frames : 0.0; }
};

// A part-like 1280x1024 scene: gradient, discs, text and noise, so PNG compresses realistically.
cv::Mat scene(int seed) {
  cv::Mat m(1024, 1280, CV_8UC1);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x)
      m.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(60 + x / 20 + y / 40);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  for (int i = 0; i < 12; ++i)
    cv::circle(m, {rng.uniform(100, 1180), rng.uniform(100, 924)}, rng.uniform(20, 90),
               cv::Scalar(rng.uniform(0, 255)), -1, cv::LINE_AA);
  cv::putText(m, std::string("FACET ").append(std::to_string(seed)), {400, 520},
              cv::FONT_HERSHEY_SIMPLEX, 3.0, cv::Scalar(240), 5, cv::LINE_AA);
  cv::Mat noise(m.size(), CV_8SC1);
  rng.fill(noise, cv::RNG::NORMAL, 0, 3);
  cv::add(m, noise, m, cv::noArray(), CV_8U);
  return m;
}

template <typename Body>
Measure timeIt(const std::string& name, Body body) {
  Measure m;
  m.name = name;
  const double cpu0 = processCpuSeconds();
  const auto t0 = Clock::now();
  body(m);
  m.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  m.cpu_s = processCpuSeconds() - cpu0;
  return m;
}

Measure replay(const std::filesystem::path& folder, const std::string& glob, int passes) {
  facet::ReplaySettings s;
  s.folder = folder;
  s.glob = glob;
  s.loop = true;
  facet::ReplayCamera camera(s);
  camera.open();
  camera.start();
  const int n = passes * static_cast<int>(camera.files().size());
  std::string name = "replay ";  // appended, not '+'-chained: GCC 12 -Wrestrict false positive
  name.append(glob).append("  facet ReplayCamera");
  return timeIt(name, [&](Measure& m) {
    for (int i = 0; i < n; ++i)
      if (camera.grab(1s).ok()) ++m.frames;
  });
}

std::string fileName(const std::filesystem::path& folder, int i, const std::string& ext) {
  std::string name = "f";
  name.append(std::to_string(i)).append(ext);
  return (folder / name).string();
}

// OpenImageIO alone (what ReplayCamera does for PNG/TIFF/BMP/JPEG; for PNM it only reads the
// header with it), to show why PNM pixels are read with OpenCV.
Measure oiioOnly(const std::filesystem::path& folder, const std::string& ext, int files,
                 int passes) {
  std::string name = "replay *";
  name.append(ext).append("  OpenImageIO read_image");
  return timeIt(name, [&](Measure& m) {
    for (int p = 0; p < passes; ++p)
      for (int i = 0; i < files; ++i) {
        auto input = OIIO::ImageInput::open(fileName(folder, i, ext));
        if (!input) continue;
        cv::Mat img(input->spec().height, input->spec().width, CV_8UC1);
        if (input->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT8, img.data)) ++m.frames;
      }
  });
}

Measure imreadBaseline(const std::filesystem::path& folder, const std::string& ext, int files,
                       int passes) {
  std::string name = "replay *";
  name.append(ext).append("  cv::imread");
  return timeIt(name, [&](Measure& m) {
    for (int p = 0; p < passes; ++p)
      for (int i = 0; i < files; ++i) {
        cv::Mat img = cv::imread(fileName(folder, i, ext), cv::IMREAD_UNCHANGED);
        if (!img.empty()) ++m.frames;
      }
  });
}

// Copies the sensor picture into every frame the fake camera sends.
void fill(ArvBuffer* buffer, void* picture, guint32, guint32, ArvPixelFormat) {
  const auto* image = static_cast<const cv::Mat*>(picture);
  const int w = arv_buffer_get_image_width(buffer);
  const int h = arv_buffer_get_image_height(buffer);
  void* data = const_cast<void*>(arv_buffer_get_data(buffer, nullptr));
  if (data && w <= image->cols && h <= image->rows)
    (*image)(cv::Rect(0, 0, w, h)).copyTo(cv::Mat(h, w, CV_8UC1, data));
}

facet::AravisSettings gigeSettings(double fps) {
  facet::AravisSettings s;
  s.address = "127.0.0.1";
  s.region = {0, 0, 1280, 1024};
  s.frame_rate_hz = fps;
  s.packet_size = 8000;
  return s;
}

Measure gigeFacet(double fps, std::chrono::milliseconds duration) {
  facet::AravisCamera camera(gigeSettings(fps));
  camera.open();
  camera.start();
  camera.grab(1s);  // first frame: stream set-up is not measured
  return timeIt("fake GigE 1280x1024 facet AravisCamera", [&](Measure& m) {
    const auto end = Clock::now() + duration;
    while (Clock::now() < end) {
      const auto r = camera.grab(500ms);
      if (r.ok()) ++m.frames;
      if (r.status == facet::GrabStatus::Incomplete) ++m.incomplete;
    }
  });
}

Measure gigeBare(double fps, std::chrono::milliseconds duration) {
  GError* error = nullptr;
  ArvCamera* camera = arv_camera_new("127.0.0.1", &error);
  if (!camera) {
    std::fprintf(stderr, "bare aravis: %s\n", error ? error->message : "?");
    g_clear_error(&error);
    return {"fake GigE 1280x1024 bare Aravis pop/push"};
  }
  // Same configuration sequence as AravisCamera::open(), minus our code around it.
  arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, nullptr);
  arv_camera_set_pixel_format_from_string(camera, "Mono8", nullptr);
  arv_camera_set_region(camera, 0, 0, 1280, 1024, nullptr);
  arv_camera_set_frame_rate(camera, fps, nullptr);
  arv_camera_clear_triggers(camera, nullptr);
  arv_camera_gv_set_packet_size(camera, 8000, nullptr);
  arv_camera_gv_set_stream_options(camera, ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
  ArvStream* stream = arv_camera_create_stream(camera, nullptr, nullptr, nullptr);
  g_object_set(stream, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_AUTO, "socket-buffer-size", 0,
               nullptr);
  const guint payload = arv_camera_get_payload(camera, nullptr);
  for (int i = 0; i < 8; ++i) arv_stream_push_buffer(stream, arv_buffer_new_allocate(payload));
  arv_camera_start_acquisition(camera, nullptr);
  if (ArvBuffer* b = arv_stream_timeout_pop_buffer(stream, 1000000))
    arv_stream_push_buffer(stream, b);
  Measure m = timeIt("fake GigE 1280x1024 bare Aravis pop/push", [&](Measure& m) {
    const auto end = Clock::now() + duration;
    while (Clock::now() < end) {
      ArvBuffer* b = arv_stream_timeout_pop_buffer(stream, 500000);
      if (!b) continue;
      if (arv_buffer_get_status(b) == ARV_BUFFER_STATUS_SUCCESS)
        ++m.frames;
      else
        ++m.incomplete;
      arv_stream_push_buffer(stream, b);
    }
  });
  arv_camera_stop_acquisition(camera, nullptr);
  g_object_unref(stream);
  g_object_unref(camera);
  return m;
}

void printRow(const Measure& m, const Measure* baseline) {
  std::printf("%-44s %7d %6d %9.1f %10.2f", m.name.c_str(), m.frames, m.incomplete, m.fps(),
              m.cpuMsPerFrame());
  if (baseline && baseline->frames > 0 && m.frames > 0)
    std::printf("   %5.2fx fps  %5.2fx cpu", m.fps() / baseline->fps(),
                m.cpuMsPerFrame() / baseline->cpuMsPerFrame());
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const bool smoke = argc > 1 && std::strcmp(argv[1], "--smoke") == 0;
  spdlog::set_level(spdlog::level::warn);
  const int files = smoke ? 4 : 20;
  const int passes = smoke ? 1 : 3;
  const auto stream_time = smoke ? 1500ms : 8000ms;
  const double gige_fps = 100.0;

  const auto folder = std::filesystem::temp_directory_path() /
                      std::string("facet_bench_camera_").append(std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  for (int i = 0; i < files; ++i) {
    const cv::Mat image = scene(i);
    cv::imwrite(fileName(folder, i, ".png"), image);
    cv::imwrite(fileName(folder, i, ".pgm"), image);
  }

  std::printf(
      "bench_camera%s: %d files 1280x1024 Mono8 x %d passes; GigE streams %.1f s at %.0f fps "
      "requested\n",
      smoke ? " --smoke" : "", files, passes, std::chrono::duration<double>(stream_time).count(),
      gige_fps);
  std::printf("%-44s %7s %6s %9s %10s   %s\n", "case", "frames", "incmpl", "fps", "cpu ms/fr",
              "ratio to baseline (fps, cpu)");

  const Measure png_cv = imreadBaseline(folder, ".png", files, passes);
  const Measure png = replay(folder, "*.png", passes);
  const Measure pgm_cv = imreadBaseline(folder, ".pgm", files, passes);
  const Measure pgm = replay(folder, "*.pgm", passes);
  const Measure pgm_oiio = oiioOnly(folder, ".pgm", files, passes);
  printRow(png_cv, nullptr);
  printRow(png, &png_cv);
  printRow(pgm_cv, nullptr);
  printRow(pgm, &pgm_cv);
  printRow(pgm_oiio, &pgm_cv);

  const cv::Mat picture = scene(99);
  ArvGvFakeCamera* fake = arv_gv_fake_camera_new("127.0.0.1", "BENCH01");
  if (!fake || !arv_gv_fake_camera_is_running(fake)) {
    std::printf("fake GigE camera could not start on 127.0.0.1: GigE rows skipped\n");
  } else {
    arv_fake_camera_set_fill_pattern(arv_gv_fake_camera_get_fake_camera(fake), &fill,
                                     const_cast<cv::Mat*>(&picture));
    const Measure ours = gigeFacet(gige_fps, stream_time);
    const Measure bare = gigeBare(gige_fps, stream_time);
    printRow(bare, nullptr);
    printRow(ours, &bare);
    std::printf("(GigE cpu includes the in-process fake camera's sending thread)\n");
  }
  if (fake) g_object_unref(fake);
  std::filesystem::remove_all(folder);
  return 0;
}
