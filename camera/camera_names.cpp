// Names of the camera enums, as printed in logs and written in station files.

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"

namespace facet {

const char* toString(PixelFormat format) {
  switch (format) {
    case PixelFormat::Mono8:
      return "Mono8";
    case PixelFormat::Mono16:
      return "Mono16";
    case PixelFormat::Bgr8:
      return "BGR8";
  }
  return "?";
}

const char* toString(GrabStatus status) {
  switch (status) {
    case GrabStatus::Ok:
      return "ok";
    case GrabStatus::Timeout:
      return "timeout";
    case GrabStatus::Incomplete:
      return "incomplete";
    case GrabStatus::EndOfStream:
      return "end_of_stream";
    case GrabStatus::Disconnected:
      return "disconnected";
    case GrabStatus::NotStarted:
      return "not_started";
    case GrabStatus::Error:
      return "error";
  }
  return "?";
}

std::string_view toString(CameraBackend backend) {
  switch (backend) {
    case CameraBackend::Replay:
      return "replay";
    case CameraBackend::Aravis:
      return "aravis";
    case CameraBackend::V4l2:
      return "v4l2";
  }
  return "?";
}

std::string_view toString(TriggerMode mode) {
  switch (mode) {
    case TriggerMode::FreeRun:
      return "free_run";
    case TriggerMode::Software:
      return "software";
    case TriggerMode::Hardware:
      return "hardware";
  }
  return "?";
}

std::string_view toString(ColourConversion conversion) {
  switch (conversion) {
    case ColourConversion::Keep:
      return "keep";
    case ColourConversion::Mono:
      return "mono";
    case ColourConversion::Colour:
      return "colour";
  }
  return "?";
}

std::optional<CameraBackend> parseCameraBackend(std::string_view name) {
  for (auto b : {CameraBackend::Replay, CameraBackend::Aravis, CameraBackend::V4l2})
    if (toString(b) == name) return b;
  return std::nullopt;
}

std::optional<TriggerMode> parseTriggerMode(std::string_view name) {
  for (auto m : {TriggerMode::FreeRun, TriggerMode::Software, TriggerMode::Hardware})
    if (toString(m) == name) return m;
  return std::nullopt;
}

std::optional<ColourConversion> parseColourConversion(std::string_view name) {
  if (name == "color") return ColourConversion::Colour;  // both spellings are accepted
  for (auto c : {ColourConversion::Keep, ColourConversion::Mono, ColourConversion::Colour})
    if (toString(c) == name) return c;
  return std::nullopt;
}

}  // namespace facet
