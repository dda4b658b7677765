#include "config/station_config.hpp"

#include <cctype>
#include <cmath>
#include <sstream>

#include "config/calibration_file.hpp"
#include "config/station_format.hpp"
#include "config/yaml_document.hpp"
#include "config/yaml_validation.hpp"
#include "plc/register_map_yaml.hpp"

namespace facet::config {
namespace {

// Non-throwing file checks: a name too long for the file system, a loop of links or a folder
// we may not read mean "not there", reported as such, never an exception out of the loader.
bool isFile(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

bool isFolder(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_directory(p, ec);
}

// Reads "<digits>" at `text[pos]`, moving `pos` past it.
std::optional<int> digitsAt(const std::string& text, std::size_t& pos) {
  const std::size_t start = pos;
  while (pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos]))) ++pos;
  if (pos == start || pos - start > 9) return std::nullopt;
  return std::stoi(text.substr(start, pos - start));
}

// Splits "file:line:column<rest>" as the PLC module writes origins and messages; `rest` is what
// follows the column. (Hand-written: std::regex trips GCC 12's -Wmaybe-uninitialized.)
std::optional<std::pair<SourceLocation, std::string>> splitLocation(const std::string& text) {
  for (std::size_t colon = text.find(':'); colon != std::string::npos;
       colon = text.find(':', colon + 1)) {
    std::size_t pos = colon + 1;
    const auto line = digitsAt(text, pos);
    if (!line || pos >= text.size() || text[pos] != ':') continue;
    ++pos;
    const auto column = digitsAt(text, pos);
    if (!column) continue;
    return std::pair{SourceLocation{text.substr(0, colon), *line, *column}, text.substr(pos)};
  }
  return std::nullopt;
}

SourceLocation parseOrigin(const std::string& origin) {
  const auto split = splitLocation(origin);
  return split && split->second.empty() ? split->first : SourceLocation{origin};
}

class StationReader {
 public:
  StationReader(const std::filesystem::path& file, Diagnostics& out) : file_(file), out_(out) {
    station_.file = std::filesystem::absolute(file).lexically_normal();
    base_ = station_.file.parent_path();
  }

  std::optional<StationConfig> read() {
    const auto yaml = readYamlFile(file_, out_);
    if (!yaml) return std::nullopt;
    validateObject(yaml->root, stationFormat().station, file_, out_);
    const YAML::Node& root = yaml->root;
    if (!root.IsMap()) return std::nullopt;
    station_.schemaVersion = static_cast<int>(readInteger(root["schema_version"]).value_or(1));
    station_.name = text(root["name"]);
    if (map(root["camera"])) readCamera(root["camera"]);
    if (map(root["plc"])) {
      station_.hasPlc = true;
      readPlc(root["plc"]);
    }
    if (const auto folder = folderPath(root["recipes"], "recipes"))
      station_.recipesFolder = *folder;
    if (map(root["results"])) readResults(root["results"]);
    if (map(root["archive"])) readArchive(root["archive"]);
    if (map(root["http"])) {
      const YAML::Node h = root["http"];
      station_.http.bind = h["bind"] ? text(h["bind"]) : station_.http.bind;
      station_.http.port = static_cast<int>(integer(h["port"], station_.http.port));
      station_.http.token = text(h["token"]);
    }
    if (map(root["calibration"])) readCalibration(root["calibration"]);
    // The station's name names its MQTT topics and its rows in a central database.
    const std::string fleetName = station_.name.empty() ? file_.stem().string() : station_.name;
    if (map(root["mqtt"]))
      station_.mqtt = readMqttSettings(root["mqtt"], file_, base_, fleetName, out_);
    if (map(root["postgres"]))
      station_.postgres = readPostgresSettings(root["postgres"], file_, base_, out_);
    if (out_.hasErrors()) return std::nullopt;
    return std::move(station_);
  }

 private:
  static bool map(const YAML::Node& n) { return n && n.IsMap(); }
  static std::string text(const YAML::Node& n) { return n ? readString(n).value_or("") : ""; }
  static long long integer(const YAML::Node& n, long long fallback) {
    return n ? readInteger(n).value_or(fallback) : fallback;
  }
  static double number(const YAML::Node& n, double fallback) {
    return n ? readNumber(n).value_or(fallback) : fallback;
  }
  // A sensor region's x, y, width or height: whole pixels, 0..2^20 (found by the station fuzz
  // target: a huge number was converted to int, which is undefined behaviour).
  int regionValue(const YAML::Node& n) {
    const double v = number(n, 0.0);
    if (v >= 0.0 && v <= double(1 << 20) && v == std::floor(v)) return static_cast<int>(v);
    error(n, "region values must be whole pixels from 0 to 1048576, not " + describe(n));
    return 0;
  }
  static bool boolean(const YAML::Node& n, bool fallback) {
    return n ? readBoolean(n).value_or(fallback) : fallback;
  }
  void error(const YAML::Node& n, std::string message) {
    out_.error(locate(file_, n), std::move(message));
  }

  // Paths in the station file are relative to it (absolute ones are allowed: the station file
  // belongs to the administrator, not to recipe authors).
  std::optional<std::filesystem::path> pathOf(const YAML::Node& n) const {
    if (!n || !n.IsScalar() || n.Scalar().empty()) return std::nullopt;
    const auto p = (base_ / n.Scalar()).lexically_normal();
    return p.has_filename() ? p : p.parent_path();  // "a/." normalises to "a/"
  }
  std::optional<std::filesystem::path> folderPath(const YAML::Node& n, const std::string& key) {
    const auto p = pathOf(n);
    if (p && !isFolder(*p)) {
      error(n, "'" + key + "' folder '" + n.Scalar() + "' does not exist (looked for " +
                   p->string() + ")");
      return std::nullopt;
    }
    return p;
  }

  void readCamera(const YAML::Node& c) {
    CameraSettings& s = station_.camera;
    const std::string backend = text(c["backend"]);
    if (const auto b = parseCameraBackend(backend)) s.backend = *b;
    if (backend == "replay" && !c["replay"])
      error(c["backend"], "backend replay needs a 'replay' section with its folder");
    if (const YAML::Node r = c["replay"]; map(r)) {
      s.replay.folder = folderPath(r["folder"], "folder").value_or(std::filesystem::path{});
      s.replay.glob = text(r["glob"]);
      s.replay.loop = boolean(r["loop"], s.replay.loop);
      s.replay.fps = number(r["fps"], s.replay.fps);
      s.replay.trigger = parseTriggerMode(text(r["trigger"])).value_or(s.replay.trigger);
      s.replay.colour = parseColourConversion(text(r["colour"])).value_or(s.replay.colour);
      s.replay.max_pixels = static_cast<std::uint64_t>(
          integer(r["max_pixels"], static_cast<long long>(s.replay.max_pixels)));
      s.replay.prefetch = static_cast<int>(integer(r["prefetch"], s.replay.prefetch));
    }
    if (const YAML::Node a = c["aravis"]; map(a)) {
      AravisSettings& v = s.aravis;
      v.device_id = text(a["device_id"]);
      v.serial = text(a["serial"]);
      v.address = text(a["address"]);
      if (a["pixel_format"]) v.pixel_format = text(a["pixel_format"]);
      if (a["exposure_us"]) v.exposure_us = number(a["exposure_us"], 0);
      if (a["gain_db"]) v.gain_db = number(a["gain_db"], 0);
      if (const YAML::Node r = a["region"]; r && r.IsSequence() && r.size() == 4) {
        v.region = {regionValue(r[0]), regionValue(r[1]), regionValue(r[2]), regionValue(r[3])};
      }
      v.packet_size = static_cast<int>(integer(a["packet_size"], v.packet_size));
      if (a["frame_rate_hz"]) v.frame_rate_hz = number(a["frame_rate_hz"], 0);
      v.trigger = parseTriggerMode(text(a["trigger"])).value_or(v.trigger);
      if (a["trigger_line"]) v.trigger_line = text(a["trigger_line"]);
      v.colour = parseColourConversion(text(a["colour"])).value_or(v.colour);
      v.buffer_count = static_cast<int>(integer(a["buffer_count"], v.buffer_count));
      v.reconnect_initial_ms =
          static_cast<int>(integer(a["reconnect_initial_ms"], v.reconnect_initial_ms));
      v.reconnect_max_ms = static_cast<int>(integer(a["reconnect_max_ms"], v.reconnect_max_ms));
    }
    if (const YAML::Node d = c["v4l2"]; map(d)) {
      V4l2Settings& v = s.v4l2;
      if (d["device"]) v.device = text(d["device"]);
      v.format = text(d["format"]);
      v.width = static_cast<int>(integer(d["width"], v.width));
      v.height = static_cast<int>(integer(d["height"], v.height));
      if (d["exposure_us"]) v.exposure_us = number(d["exposure_us"], 0);
      if (d["gain"]) v.gain = static_cast<int>(integer(d["gain"], 0));
      v.colour = parseColourConversion(text(d["colour"])).value_or(v.colour);
      v.buffer_count = static_cast<int>(integer(d["buffer_count"], v.buffer_count));
      v.reconnect_initial_ms =
          static_cast<int>(integer(d["reconnect_initial_ms"], v.reconnect_initial_ms));
      v.reconnect_max_ms = static_cast<int>(integer(d["reconnect_max_ms"], v.reconnect_max_ms));
    }
    if (const YAML::Node r = c["scans"]; map(r)) {
      s.scans.folder = folderPath(r["folder"], "folder").value_or(std::filesystem::path{});
      s.scans.glob = text(r["glob"]);
      s.scans.loop = boolean(r["loop"], s.scans.loop);
      s.scans.max_range_m = number(r["max_range_m"], s.scans.max_range_m);
    }
  }

  void readPlc(const YAML::Node& p) {
    plc::PlcSettings& s = station_.plc;
    using std::chrono::milliseconds;
    if (text(p["role"]) == "server") s.role = plc::LinkRole::Server;
    if (text(p["mode"]) == "free_run") s.mode = plc::HandshakeMode::FreeRun;
    if (text(p["transport"]) == "rtu") s.transport = plc::Transport::Rtu;
    if (p["host"]) s.host = text(p["host"]);
    s.port = static_cast<int>(integer(p["port"], s.port));
    s.unitId = static_cast<int>(integer(p["unit_id"], s.unitId));
    if (p["serial_device"]) s.serialDevice = text(p["serial_device"]);
    s.baudRate = static_cast<int>(integer(p["baud_rate"], s.baudRate));
    if (p["parity"] && !text(p["parity"]).empty()) s.parity = text(p["parity"])[0];
    s.dataBits = static_cast<int>(integer(p["data_bits"], s.dataBits));
    s.stopBits = static_cast<int>(integer(p["stop_bits"], s.stopBits));
    s.responseTimeout = milliseconds(integer(p["response_timeout_ms"], s.responseTimeout.count()));
    s.pollPeriod = milliseconds(integer(p["poll_period_ms"], s.pollPeriod.count()));
    s.heartbeatPeriod = milliseconds(integer(p["heartbeat_period_ms"], s.heartbeatPeriod.count()));
    s.reconnectInitial =
        milliseconds(integer(p["reconnect_initial_ms"], s.reconnectInitial.count()));
    s.reconnectMax = milliseconds(integer(p["reconnect_max_ms"], s.reconnectMax.count()));
    s.queueCapacity = static_cast<std::size_t>(
        integer(p["queue_capacity"], static_cast<long long>(s.queueCapacity)));
    if (p["word_order"])
      station_.wordOrder = plc::parseWordOrder(text(p["word_order"])).value_or(station_.wordOrder);
    if (s.transport == plc::Transport::Rtu && s.role == plc::LinkRole::Server)
      error(p["transport"], "transport rtu works in the client role only");
    if (s.reconnectMax < s.reconnectInitial)
      error(p["reconnect_max_ms"] ? p["reconnect_max_ms"] : p,
            "'reconnect_max_ms' must be at least 'reconnect_initial_ms'");

    const YAML::Node m = p["register_map"];
    if (!map(m)) return;
    // The PLC module parses and validates its own map; its messages carry file:line:column.
    const std::size_t errorsBefore = out_.errorCount();
    validateObject(m, stationFormat().registerMap, file_, out_);
    if (out_.errorCount() > errorsBefore) return;  // the PLC parser would repeat the first one
    try {
      station_.registerMap = plc::parseRegisterMap(m, file_.string());
    } catch (const plc::RegisterMapError& e) {
      std::istringstream lines(e.what());
      std::string line;
      while (std::getline(lines, line)) {
        const auto split = splitLocation(line);
        if (split && split->first.file == file_ && split->second.starts_with(": "))
          out_.error(split->first, split->second.substr(2));
        else
          error(m, "register map: " + line);
      }
    }
  }

  void readResults(const YAML::Node& r) {
    const auto db = pathOf(r["database"]);
    if (!db) return;
    station_.results.database = *db;
    station_.results.keepDays = number(r["keep_days"], 0.0);
    station_.results.keepParts = integer(r["keep_parts"], 0);
    if (!isFolder(db->parent_path()))
      error(r["database"],
            "the folder of 'database' (" + db->parent_path().string() + ") does not exist");
  }

  void readArchive(const YAML::Node& a) {
    ArchiveSettings& s = station_.archive;
    s.folder = pathOf(a["folder"]).value_or(std::filesystem::path{});
    s.quotaMb = number(a["quota_mb"], 0.0);
    const std::string keep = text(a["keep"]);
    s.keep = keep == "all"    ? ArchiveSettings::Keep::All
             : keep == "none" ? ArchiveSettings::Keep::None
                              : ArchiveSettings::Keep::Failed;
    if (!s.folder.empty() && !isFolder(s.folder.parent_path()))
      error(a["folder"], "the folder containing 'folder' (" + s.folder.parent_path().string() +
                             ") does not exist");
  }

  void readCalibration(const YAML::Node& c) {
    Calibration& cal = station_.calibration;
    cal.mmPerPixel = number(c["mm_per_pixel"], 0.0);
    if (c["file"]) {
      const auto p = pathOf(c["file"]);
      if (!p) return;
      if (!isFile(*p)) {
        error(c["file"], "calibration file '" + c["file"].Scalar() + "' does not exist");
        return;
      }
      cal.file = *p;
      readCalibrationFile(c["file"], *p);
    }
    if (cal.mmPerPixel <= 0 && !c["mm_per_pixel"] && !out_.hasErrors())
      error(c, "calibration needs 'mm_per_pixel' (here or in the calibration file)");
  }

  void readCalibrationFile(const YAML::Node& key, const std::filesystem::path& p) {
    Calibration& cal = station_.calibration;
    Diagnostics problems;
    const auto data = config::readCalibrationFile(p, problems);
    // The calibration file's own problems name that file (and line); the station's key says
    // which file it was.
    out_.append(problems);
    if (!data) {
      error(key, "calibration file '" + key.Scalar() + "' is not usable (see above)");
      return;
    }
    if (cal.mmPerPixel <= 0) cal.mmPerPixel = data->mmPerPixel;
    if (data->camera) {
      cal.cameraMatrix = cv::Mat(data->camera->cameraMatrix, true);
      cal.distortion = data->camera->distortion.clone();
      cal.imageSize = data->camera->imageSize;
    }
    cal.plane = data->plane;
    // With a plane, the scale-only fallback is the plane's scale at the image centre.
    if (cal.mmPerPixel <= 0 && cal.plane && !cal.imageSize.empty())
      if (const auto mapping = cal.worldMapping())
        cal.mmPerPixel = mapping->mmPerPixelAt(
            {(cal.imageSize.width - 1) / 2.0, (cal.imageSize.height - 1) / 2.0});
  }

  const std::filesystem::path& file_;
  Diagnostics& out_;
  std::filesystem::path base_;
  StationConfig station_;
};

}  // namespace

std::string Calibration::kind() const {
  if (!cameraMatrix.empty() && plane) return "lens model + plane";
  if (!cameraMatrix.empty()) return "lens model, scale only";
  return "scale only, no lens model";
}

std::optional<WorldMapping> Calibration::worldMapping() const {
  if (cameraMatrix.empty() || !plane) return std::nullopt;
  return WorldMapping(CameraModel{cv::Matx33d(cameraMatrix), distortion, imageSize}, *plane);
}

std::vector<RegisterUse> StationConfig::reservedRegisters() const {
  std::vector<RegisterUse> uses;
  for (const auto& signal : plc::namedSignals(registerMap)) {
    if (signal.location->table != plc::Table::HoldingRegister) continue;
    uses.push_back({"station " + signal.name, signal.location->address, 1,
                    parseOrigin(signal.location->origin), true});
  }
  for (const auto& r : registerMap.results)
    uses.push_back({"station result." + r.name, r.address, plc::registerCount(r.type),
                    parseOrigin(r.origin), true});
  return uses;
}

RecipeLoadOptions StationConfig::recipeLoadOptions() const {
  RecipeLoadOptions options;
  options.root = recipesFolder;
  options.reservedRegisters = reservedRegisters();
  options.defaultWordOrder = wordOrder;
  return options;
}

plc::RegisterMap StationConfig::registerMapFor(const Recipe& recipe) const {
  plc::RegisterMap map = registerMap;
  for (const auto& [check, step] : recipe.plcOutputs()) map.results.push_back(check->plc->output);
  return map;
}

StationLoadResult loadStationConfig(const std::filesystem::path& file) {
  StationLoadResult result;
  result.station = StationReader(file, result.diagnostics).read();
  return result;
}

}  // namespace facet::config
