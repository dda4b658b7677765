// fake_gige_camera: Aravis' fake GigE Vision camera on 127.0.0.1:3956 serving recorded images.
//
//   fake_gige_camera --folder recipes/demo/bracket_shape [--serial FACETIT1]
//
// Frame k (k = 0, 1, ...) shows image k mod N of the folder's *.png files in name order, grey,
// pasted at the top-left of the requested region (the rest is filled with the image's corner
// grey). stdout, one line each: "listening <serial> <N>" once the camera answers on GVCP, then
// "frame <k> <raw frame id> <file name>" per frame served. Runs until SIGTERM or SIGINT.
#include <arv.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace {

struct Recording {
  std::vector<std::string> names;
  std::vector<cv::Mat> images;  // CV_8UC1
  std::mutex mutex;
  std::uint64_t served = 0;
};

Recording& recording() {
  static Recording r;
  return r;
}

// Runs on the fake camera's thread, once per frame.
void fill(ArvBuffer* buffer, void*, guint32, guint32, ArvPixelFormat format) {
  auto& r = recording();
  std::lock_guard lock(r.mutex);
  const std::uint64_t k = r.served++;
  const std::size_t index = k % r.images.size();
  const cv::Mat& image = r.images[index];
  const int width = static_cast<int>(arv_buffer_get_image_width(buffer));
  const int height = static_cast<int>(arv_buffer_get_image_height(buffer));
  void* data = const_cast<void*>(arv_buffer_get_data(buffer, nullptr));
  if (data && format == ARV_PIXEL_FORMAT_MONO_8) {
    cv::Mat target(height, width, CV_8UC1, data);
    target.setTo(image.at<unsigned char>(0, 0));
    const cv::Rect common(0, 0, std::min(width, image.cols), std::min(height, image.rows));
    image(common).copyTo(target(common));
  }
  std::printf("frame %llu %llu %s\n", static_cast<unsigned long long>(k),
              static_cast<unsigned long long>(arv_buffer_get_frame_id(buffer)),
              r.names[index].c_str());
  std::fflush(stdout);
}

int usage(const char* message) {
  std::fprintf(stderr, "fake_gige_camera: %s\nusage: fake_gige_camera --folder DIR [--serial S]\n",
               message);
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path folder;
  std::string serial = "FACETIT1";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--folder")
      folder = argv[i + 1];
    else if (key == "--serial")
      serial = argv[i + 1];
    else
      return usage(("unknown option " + key).c_str());
  }
  if (folder.empty()) return usage("--folder is required");
  std::error_code error;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error))
    if (entry.path().extension() == ".png") files.push_back(entry.path());
  if (error) return usage((folder.string() + ": " + error.message()).c_str());
  std::sort(files.begin(), files.end());
  auto& r = recording();
  for (const auto& file : files) {
    cv::Mat image = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    if (image.empty()) return usage((file.string() + ": not a readable image").c_str());
    r.names.push_back(file.filename().string());
    r.images.push_back(image);
  }
  if (r.images.empty()) return usage((folder.string() + ": no *.png files").c_str());

  // SIGTERM/SIGINT are blocked in every thread (Aravis starts its own) and taken below.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  ArvGvFakeCamera* camera = arv_gv_fake_camera_new("127.0.0.1", serial.c_str());
  if (!camera || !arv_gv_fake_camera_is_running(camera)) {
    std::fprintf(stderr,
                 "fake_gige_camera: cannot start the fake camera on 127.0.0.1:3956 (port in "
                 "use by another fake camera?)\n");
    if (camera) g_object_unref(camera);
    return 2;
  }
  arv_fake_camera_set_fill_pattern(arv_gv_fake_camera_get_fake_camera(camera), &fill, nullptr);
  std::printf("listening %s %zu\n", serial.c_str(), r.images.size());
  std::fflush(stdout);

  // Until SIGTERM or SIGINT (a test starting this also makes it die with the test).
  sigwaitinfo(&signals, nullptr);
  g_object_unref(camera);
  return 0;
}
