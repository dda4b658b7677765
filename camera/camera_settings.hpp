#pragma once
// CameraSettings: everything needed to build a camera, as a plain struct. The config module
// fills it from the station file; makeCamera() (camera_factory.hpp) turns it into a Camera.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace facet {

enum class CameraBackend { Replay, Aravis, V4l2 };

enum class TriggerMode {
  FreeRun,   // the camera streams at its frame rate
  Software,  // one frame per Camera::softwareTrigger()
  Hardware,  // one frame per edge on a trigger input line (Aravis only)
};

// What the frames handed to inspection look like.
enum class ColourConversion {
  Keep,    // as recorded / as the sensor delivers (Bayer is still demosaiced to BGR)
  Mono,    // colour is converted to grey (16-bit stays 16-bit)
  Colour,  // grey is expanded to BGR
};

// A rectangle on the sensor in pixels; width or height 0 means "full sensor".
struct SensorRegion {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;
};

// Replay of a folder of recorded images (PNG, TIFF 8/16, BMP, PGM/PPM, JPEG).
struct ReplaySettings {
  std::filesystem::path folder;  // required
  // File-name pattern with '*' and '?' (no path separators). Empty: every file whose extension
  // is a supported image type. Files are taken in natural order (img2 before img10).
  std::string glob;
  bool loop = false;  // start again after the last file instead of EndOfStream
  // Frames per second in free-run mode; 0 = as fast as grab() is called.
  double fps = 0.0;
  TriggerMode trigger = TriggerMode::FreeRun;  // FreeRun or Software
  ColourConversion colour = ColourConversion::Keep;
  // Files whose header announces more pixels (width * height) than this are skipped before
  // any pixel memory is allocated (guards against corrupt or hostile headers). Default 2^28.
  std::uint64_t max_pixels = std::uint64_t{1} << 28;
  // false: an unreadable file is skipped, and grab() goes on to the next one (counted in
  // CameraHealth::skipped_files). true: grab() returns GrabStatus::Error for it, with
  // frame.source naming the file and frame.metadata its sidecar, so that a caller that treats
  // every recorded file as a part (facetd) can answer it as "not inspected". Once per file: a
  // looping replay skips it on later passes.
  bool report_unreadable = false;
  // Files read and decoded ahead of grab() by a background thread, as a real camera has its
  // frame in memory when it is triggered (exposure and transfer aside). Bounds the memory held:
  // at most `prefetch` decoded frames plus the one being read. 0 = each file is read inside
  // grab(), on the caller's time.
  int prefetch = 2;
};

// A GigE Vision / USB3 Vision camera through Aravis.
struct AravisSettings {
  // How to find the camera; the first non-empty one is used, all empty = first camera found.
  std::string device_id;  // Aravis device id, e.g. "Aravis-Fake-GV01" (vendor-model-serial)
  std::string serial;     // DeviceSerialNumber
  std::string address;    // IPv4 address of a GigE camera, opened without discovery
  // GenICam PixelFormat name: Mono8, Mono16, RGB8, BayerRG8/BayerGR8/BayerGB8/BayerBG8.
  std::string pixel_format = "Mono8";
  std::optional<double> exposure_us;    // ExposureTime in microseconds; unset = leave as is
  std::optional<double> gain_db;        // Gain in dB; unset = leave as is
  SensorRegion region;                  // full sensor by default
  int packet_size = 0;                  // GigE packet size in bytes; 0 = negotiate automatically
  std::optional<double> frame_rate_hz;  // AcquisitionFrameRate; unset = leave as is
  TriggerMode trigger = TriggerMode::FreeRun;
  std::string trigger_line = "Line1";  // TriggerSource in Hardware mode
  ColourConversion colour = ColourConversion::Keep;
  int buffer_count = 8;  // stream buffers queued to the driver
  // Reconnection after the camera is lost: first wait, doubled per failure up to the maximum.
  int reconnect_initial_ms = 200;
  int reconnect_max_ms = 5000;
};

// A USB (UVC) camera through V4L2.
struct V4l2Settings {
  std::string device = "/dev/video0";
  // FourCC to ask for: "GREY", "YUYV" or "MJPG"; empty = the first of these the device offers.
  std::string format;
  int width = 0;   // pixels; 0 = the driver's current width
  int height = 0;  // pixels; 0 = the driver's current height
  // V4L2_CID_EXPOSURE_ABSOLUTE is in units of 100 us; we take microseconds and convert.
  std::optional<double> exposure_us;  // unset = leave as is (auto exposure stays on)
  std::optional<int> gain;            // V4L2_CID_GAIN in the device's own units
  ColourConversion colour = ColourConversion::Keep;
  int buffer_count = 4;  // mmap buffers
  int reconnect_initial_ms = 200;
  int reconnect_max_ms = 5000;
};

// Replay of recorded 2D range scans (for scan recipes), see scan_source.hpp.
struct ScanReplaySettings {
  std::filesystem::path folder;  // required when a recipe uses scans
  // File-name pattern with '*' and '?'; empty = every *.csv, *.log, *.clf, *.carmen and their
  // .gz forms.
  std::string glob;
  bool loop = false;
  // Ranges at or beyond this are "no return" and dropped (metres); 0 = the scan readers'
  // default of 80 m (CARMEN writes about 81.9 for no return).
  double max_range_m = 0.0;
};

struct CameraSettings {
  CameraBackend backend = CameraBackend::Replay;
  ReplaySettings replay;
  AravisSettings aravis;
  V4l2Settings v4l2;
  ScanReplaySettings scans;  // independent of `backend`
};

// Names as written in the station file ("replay", "aravis", "v4l2"; "free_run", "software",
// "hardware"; "keep", "mono", "colour"). parse* returns nullopt for an unknown name.
std::string_view toString(CameraBackend backend);
std::string_view toString(TriggerMode mode);
std::string_view toString(ColourConversion conversion);
std::optional<CameraBackend> parseCameraBackend(std::string_view name);
std::optional<TriggerMode> parseTriggerMode(std::string_view name);
std::optional<ColourConversion> parseColourConversion(std::string_view name);

}  // namespace facet
