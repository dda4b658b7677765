// fake_gige_camera: Aravis' fake GigE Vision camera on 127.0.0.1:3956 serving recorded images.
//
//   fake_gige_camera --folder recipes/demo/bracket_shape [--serial FACETIT1] [--drop-every K]
//
// Frame k (k = 0, 1, ...) shows image k mod N of the folder's *.png files in name order, grey,
// pasted at the top-left of the requested region (the rest is filled with the image's corner
// grey). stdout, one line each: "listening <serial> <N>" once the camera answers on GVCP, then
// "frame <k> <raw frame id> <file name>" per frame served, with " incomplete" appended when one
// of its packets is withheld. Runs until SIGTERM or SIGINT.
//
// --drop-every K withholds one GVSP data packet (the second) of frames K-1, 2K-1, ...: a
// deterministic packet loss that a test can account for frame by frame (no tc/netem needed).
// The packet is lost for good: Aravis' fake camera does not answer packet resend requests
// (GVCP PACKETRESEND is not among the commands it handles). Aravis 0.8.26's receiver does not
// even ask here (its resend check runs when a later packet of the frame arrives, and the whole
// burst beats the first packet timeout): it closes the frame after its frame retention time
// (100 ms) with status ARV_BUFFER_STATUS_TIMEOUT.
#include <arv.h>
#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
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
  std::uint64_t drop_every = 0;  // 0: no packet withheld
};

// The GVSP data packet (by packet id within its block) withheld from a frame: the second, so
// the frame has a leader, data before and after the gap, and a trailer.
constexpr std::uint32_t kWithheldPacketId = 2;

// Set by fill() for a frame that loses a packet, cleared by the send that withholds it. Both
// run on the fake camera's one thread, fill() just before that frame's packets are sent.
std::atomic<bool> withhold_pending{false};
std::atomic<std::uint32_t> withhold_block{0};

Recording& recording() {
  static Recording r;
  return r;
}

// Runs on the fake camera's thread, once per frame.
void fill(ArvBuffer* buffer, void*, guint32, guint32, ArvPixelFormat format) {
  auto& r = recording();
  std::lock_guard lock(r.mutex);
  const std::uint64_t k = r.served++;
  if (withhold_pending.exchange(false))
    std::fprintf(stderr, "fake_gige_camera: the previous frame had no packet %u to withhold\n",
                 kWithheldPacketId);
  const bool incomplete = r.drop_every > 0 && (k + 1) % r.drop_every == 0;
  if (incomplete) {
    withhold_block = static_cast<std::uint32_t>(arv_buffer_get_frame_id(buffer) & 0xFFFF);
    withhold_pending = true;
  }
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
  std::printf("frame %llu %llu %s%s\n", static_cast<unsigned long long>(k),
              static_cast<unsigned long long>(arv_buffer_get_frame_id(buffer)),
              r.names[index].c_str(), incomplete ? " incomplete" : "");
  std::fflush(stdout);
}

// Whether `data` is the GVSP data packet fill() asked to withhold. Standard (16-bit block id)
// GVSP header: status (2 bytes), block id (2), then content type (1) and packet id (3), all
// big-endian; content type 3 is a payload packet.
bool isWithheldPacket(const gchar* data, gsize size) {
  if (!withhold_pending || size < 8) return false;
  const auto* b = reinterpret_cast<const unsigned char*>(data);
  const std::uint32_t block = (std::uint32_t{b[2]} << 8) | b[3];
  const std::uint32_t content = b[4] & 0x7F;
  const std::uint32_t packet = (std::uint32_t{b[5]} << 16) | (std::uint32_t{b[6]} << 8) | b[7];
  return b[0] == 0 && b[1] == 0 && content == 3 && block == withhold_block &&
         packet == kWithheldPacketId;
}

int usage(const char* message) {
  std::fprintf(stderr,
               "fake_gige_camera: %s\nusage: fake_gige_camera --folder DIR [--serial S] "
               "[--drop-every K]\n",
               message);
  return 1;
}

}  // namespace

// The fake camera sends every GVCP and GVSP packet with g_socket_send_to(); this definition in
// the executable takes precedence over GIO's for libaravis, so a packet can be withheld here
// and everything else is passed on to GIO.
extern "C" gssize g_socket_send_to(GSocket* socket, GSocketAddress* address, const gchar* buffer,
                                   gsize size, GCancellable* cancellable, GError** error) {
  using SendTo =
      gssize (*)(GSocket*, GSocketAddress*, const gchar*, gsize, GCancellable*, GError**);
  static const auto real = reinterpret_cast<SendTo>(dlsym(RTLD_NEXT, "g_socket_send_to"));
  if (isWithheldPacket(buffer, size)) {
    withhold_pending = false;
    return static_cast<gssize>(size);  // "sent": lost on the way
  }
  return real(socket, address, buffer, size, cancellable, error);
}

int main(int argc, char** argv) {
  std::filesystem::path folder;
  std::string serial = "FACETIT1";
  if (argc % 2 == 0) return usage("every option takes a value");
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--folder")
      folder = argv[i + 1];
    else if (key == "--serial")
      serial = argv[i + 1];
    else if (key == "--drop-every") {
      char* end = nullptr;
      const long k = std::strtol(argv[i + 1], &end, 10);
      if (*end != '\0' || k < 1) return usage("--drop-every needs a whole number >= 1");
      recording().drop_every = static_cast<std::uint64_t>(k);
    } else
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
