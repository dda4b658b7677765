#include "config/station_format.hpp"

namespace facet::config {
namespace {

using F = FieldType;

FieldSpec text(std::string name, std::string description, nlohmann::json def = nullptr) {
  return {.name = std::move(name),
          .type = F::String,
          .description = std::move(description),
          .defaultValue = std::move(def)};
}

FieldSpec integer(std::string name, std::string description, double minimum, double maximum,
                  nlohmann::json def = nullptr) {
  return {.name = std::move(name),
          .type = F::Integer,
          .description = std::move(description),
          .minimum = minimum,
          .maximum = maximum,
          .defaultValue = std::move(def)};
}

FieldSpec positive(std::string name, std::string description, nlohmann::json def = nullptr) {
  return {.name = std::move(name),
          .type = F::Number,
          .description = std::move(description),
          .minimum = 0.0,
          .exclusiveMinimum = true,
          .defaultValue = std::move(def)};
}

FieldSpec choice(std::string name, std::string description, std::vector<std::string> choices,
                 nlohmann::json def = nullptr) {
  return {.name = std::move(name),
          .type = F::Enum,
          .description = std::move(description),
          .choices = std::move(choices),
          .defaultValue = std::move(def)};
}

FieldSpec flag(std::string name, std::string description, bool def) {
  return {.name = std::move(name),
          .type = F::Boolean,
          .description = std::move(description),
          .defaultValue = def};
}

FieldSpec section(std::string name, std::string description, const ObjectSpec* object,
                  bool required = false) {
  return {.name = std::move(name),
          .type = F::Object,
          .description = std::move(description),
          .required = required,
          .object = object};
}

FieldSpec path(std::string name, std::string description, bool required = false) {
  return {.name = std::move(name),
          .type = F::Path,
          .description = std::move(description),
          .required = required};
}

const std::vector<std::string> kColour{"keep", "mono", "colour", "color"};
constexpr double kMaxInt = 2147483647.0;

}  // namespace

StationFormat::StationFormat() {
  replay = {
      "replay camera",
      "Replay of a folder of recorded images.",
      {path("folder", "Folder of recorded images, relative to the station file.", true),
       text("glob", "File-name pattern with * and ?; default: every image file."),
       flag("loop", "Start again after the last file.", false),
       {.name = "fps",
        .type = F::Number,
        .description = "Frames per second: the rate in free_run, the highest rate with a "
                       "software trigger; 0 = as fast as grabbed.",
        .minimum = 0.0,
        .defaultValue = 0.0},
       choice("trigger", "free_run or software.", {"free_run", "software"}, "free_run"),
       choice("colour", "keep, mono or colour.", kColour, "keep"),
       integer("max_pixels", "Files announcing more pixels are skipped.", 1, 9.0e15, 268435456),
       integer("prefetch", "Files read ahead of the trigger; 0 = read when grabbed.", 0, 16, 2)}};
  aravis = {
      "aravis camera",
      "A GigE Vision / USB3 Vision camera through Aravis.",
      {text("device_id", "Aravis device id (vendor-model-serial)."),
       text("serial", "DeviceSerialNumber."),
       text("address", "IPv4 address of a GigE camera, opened without discovery."),
       choice("pixel_format", "GenICam PixelFormat.",
              {"Mono8", "Mono16", "RGB8", "BayerRG8", "BayerGR8", "BayerGB8", "BayerBG8"}, "Mono8"),
       positive("exposure_us", "ExposureTime, microseconds; unset = leave as is."),
       {.name = "gain_db", .type = F::Number, .description = "Gain, dB."},
       {.name = "region",
        .type = F::Rect,
        .description = "[x, y, width, height] on the sensor, pixels; default: full sensor.",
        .minimum = 0.0},
       integer("packet_size", "GigE packet size, bytes; 0 = negotiate.", 0, 65535, 0),
       positive("frame_rate_hz", "AcquisitionFrameRate."),
       choice("trigger", "free_run, software or hardware.", {"free_run", "software", "hardware"},
              "free_run"),
       text("trigger_line", "TriggerSource in hardware mode.", "Line1"),
       choice("colour", "keep, mono or colour.", kColour, "keep"),
       integer("buffer_count", "Stream buffers.", 1, 256, 8),
       integer("reconnect_initial_ms", "First wait after losing the camera.", 1, kMaxInt, 200),
       integer("reconnect_max_ms", "Longest wait between reconnection attempts.", 1, kMaxInt,
               5000)}};
  v4l2 = {"v4l2 camera",
          "A USB (UVC) camera through V4L2.",
          {text("device", "Device node.", "/dev/video0"),
           choice("format", "FourCC; default: the first of GREY, YUYV, MJPG offered.",
                  {"GREY", "YUYV", "MJPG"}),
           integer("width", "Pixels; 0 = the driver's current width.", 0, 65535, 0),
           integer("height", "Pixels; 0 = the driver's current height.", 0, 65535, 0),
           positive("exposure_us", "Exposure, microseconds; unset = auto exposure."),
           integer("gain", "V4L2 gain in the device's units.", -kMaxInt, kMaxInt),
           choice("colour", "keep, mono or colour.", kColour, "keep"),
           integer("buffer_count", "mmap buffers.", 1, 64, 4),
           integer("reconnect_initial_ms", "First wait after losing the camera.", 1, kMaxInt, 200),
           integer("reconnect_max_ms", "Longest wait between reconnection attempts.", 1, kMaxInt,
                   5000)}};
  scans = {"scan replay",
           "Replay of recorded 2D range scans, for scan_align recipes.",
           {path("folder", "Folder of scans (CSV or CARMEN logs).", true),
            text("glob", "File-name pattern; default: every scan file."),
            flag("loop", "Start again after the last file.", false),
            {.name = "max_range_m",
             .type = F::Number,
             .description =
                 "Ranges at or beyond this are dropped, metres; 0 = the readers' default (80 m).",
             .minimum = 0.0,
             .defaultValue = 0.0}}};
  camera = {"camera",
            "Where frames come from.",
            {choice("backend", "replay, aravis or v4l2.", {"replay", "aravis", "v4l2"}),
             section("replay", "Settings of the replay backend.", &replay),
             section("aravis", "Settings of the aravis backend.", &aravis),
             section("v4l2", "Settings of the v4l2 backend.", &v4l2),
             section("scans", "Recorded range scans.", &scans)}};
  camera.fields[0].required = true;

  location = {"register location",
              "{coil: N}, {register: N} or {register: N, bit: B}.",
              {integer("coil", "Coil address.", 0, 65535),
               integer("register", "Holding register address.", 0, 65535),
               integer("bit", "Bit of the holding register, 0..15.", 0, 15)}};
  control = {"control signals",
             "Signals the PLC writes.",
             {section("trigger", "Flag; a rising edge starts an inspection.", &location),
              section("result_ack", "Flag; a rising edge acknowledges a result.", &location),
              section("recipe_select", "Number; the recipe id the PLC asks for.", &location),
              section("enable", "Flag; when 0 triggers are ignored.", &location)}};
  status = {"status signals", "Signals the daemon writes.", {}};
  for (const char* name :
       {"ready", "busy", "result_valid", "pass", "completed_toggle", "missed_trigger", "error",
        "error_code", "heartbeat", "inspection_counter", "active_recipe"})
    status.fields.push_back(section(name, "Where the daemon writes it.", &location));
  result = {"result output",
            "A named output in holding registers.",
            {{.name = "name", .type = F::String, .description = "Output name.", .required = true},
             integer("register", "First holding register.", 0, 65535),
             choice("type", "Encoding.",
                    {"int16", "int32", "scaled_int16", "scaled_int32", "float32"}, "float32"),
             {.name = "factor",
              .type = F::Number,
              .description = "Scaled types: the register holds round(value * factor)."},
             choice("word_order", "Byte order of 32-bit values.", {"ABCD", "CDAB", "BADC", "DCBA"},
                    "ABCD")}};
  result.fields[1].required = true;
  registerMap = {"register map",
                 "Where every handshake signal lives in the PLC's Modbus address space.",
                 {integer("address_base", "0: addresses are wire addresses; 1: 1-based.", 0, 1, 0),
                  section("control", "Signals the PLC writes.", &control),
                  section("status", "Signals the daemon writes.", &status),
                  {.name = "results",
                   .type = F::ObjectList,
                   .description = "Fixed outputs; recipes add their own checks' outputs.",
                   .object = &result}}};
  plc = {
      "plc",
      "The Modbus link to the line's PLC.",
      {choice("role", "client: the daemon connects to the PLC; server: the PLC polls it.",
              {"client", "server"}, "client"),
       choice("mode", "Handshake: triggered or free_run.", {"triggered", "free_run"}, "triggered"),
       choice("transport", "tcp or rtu.", {"tcp", "rtu"}, "tcp"),
       text("host", "PLC address (client) or listen address (server).", "127.0.0.1"),
       integer("port", "TCP port; a server may use 0 for any free port.", 0, 65535, 502),
       integer("unit_id", "Modbus unit id.", 0, 255, 1),
       text("serial_device", "RTU serial port.", "/dev/ttyUSB0"),
       integer("baud_rate", "RTU baud rate.", 1, 10000000, 19200),
       choice("parity", "RTU parity.", {"N", "E", "O"}, "E"),
       integer("data_bits", "RTU data bits.", 5, 8, 8),
       integer("stop_bits", "RTU stop bits.", 1, 2, 1),
       integer("response_timeout_ms", "Wait for one answer, ms.", 1, 600000, 500),
       integer("poll_period_ms", "Control signal poll period, ms.", 1, 60000, 2),
       integer("heartbeat_period_ms", "Heartbeat period, ms; 0 = off.", 0, 600000, 1000),
       integer("reconnect_initial_ms", "First wait after a lost link, ms.", 1, 600000, 100),
       integer("reconnect_max_ms", "Longest wait between reconnections, ms.", 1, 600000, 500),
       integer("queue_capacity", "Results waiting for the PLC at most.", 1, 100000, 64),
       choice("word_order", "Byte order of recipe outputs that do not name their own.",
              {"ABCD", "CDAB", "BADC", "DCBA"}, "ABCD"),
       section("register_map", "Register map (checked by the PLC module).", &registerMap, true)}};
  plc.fields.back().validatedByOwner = true;

  results = {
      "results store",
      "SQLite file the results are stored in.",
      {path("database", "SQLite file, relative to the station file; its folder must exist.", true),
       positive("keep_days", "Parts older than this many days are deleted; unset = keep."),
       integer("keep_parts", "At most this many newest parts are kept; unset = all.", 1, 9.0e15)}};
  archive = {"image archive",
             "Where inspected images are kept.",
             {path("folder", "Archive folder, relative to the station file.", true),
              positive("quota_mb", "Largest size of the archive, MB; the oldest go first."),
              choice("keep", "Which images to keep.", {"all", "fail", "none"}, "fail")}};
  archive.fields[1].required = true;
  http = {"http",
          "Health, metrics and dashboard.",
          {text("bind", "Listen address.", "127.0.0.1"),
           integer("port", "Listen port; 0 = any free port.", 0, 65535, 8080),
           text("token", "Bearer token required for the dashboard's write actions.")}};
  calibration = {"calibration",
                 "Pixels to millimetres: mm_per_pixel, or an OpenCV calibration file "
                 "(camera_matrix, distortion_coefficients and mm_per_pixel).",
                 {positive("mm_per_pixel", "Millimetres per pixel in the part's plane."),
                  path("file",
                       "OpenCV FileStorage file (YAML/XML) from checkerboard calibration, "
                       "relative to the station file.")}};

  mqttTls = {
      "mqtt tls",
      "TLS to the broker; on when ca_file is set.",
      {path("ca_file", "CA certificate(s) the broker's certificate is checked against.", true),
       path("cert_file", "Client certificate (with key_file)."),
       path("key_file", "Client private key (with cert_file)."),
       flag("insecure", "Do not check the broker's host name (test brokers only).", false)}};
  mqtt = {
      "mqtt",
      "Each part's result as JSON on <topic_prefix>/<station>/result (QoS 1); the station's "
      "status retained on <topic_prefix>/<station>/status, last will \"offline\".",
      {text("host", "Broker address.", "127.0.0.1"),
       integer("port", "Broker port; default 1883, 8883 with tls.", 1, 65535),
       text("client_id", "MQTT client id; default facet-<station name>."),
       text("topic_prefix", "First topic levels.", "facet"),
       text("username", "User name at the broker."),
       text("password", "Password at the broker (needs username)."),
       integer("keepalive_s", "MQTT keep-alive, seconds.", 5, 65535, 30),
       integer("reconnect_max_ms", "Longest wait between reconnections, ms.", 100, 600000, 5000),
       section("tls", "TLS settings.", &mqttTls),
       path("outbox", "Folder of results waiting for the broker; default mqtt-outbox."),
       positive("outbox_quota_mb", "Largest size of the outbox, MB; the oldest go first.", 64)}};
  postgres = {
      "postgres",
      "A central PostgreSQL database with the tables of the results store (one station "
      "column more), written off the inspection path.",
      {{.name = "connection",
        .type = F::String,
        .description = "libpq connection string, e.g. \"host=db port=5432 dbname=facet "
                       "user=station1\".",
        .required = true},
       text("password", "Password, kept apart from the connection string."),
       integer("connect_timeout_s", "Wait for a connection, seconds.", 1, 600, 5),
       integer("reconnect_max_ms", "Longest wait between reconnections, ms.", 100, 600000, 5000),
       integer("batch_parts", "Parts per transaction when catching up.", 1, 10000, 50),
       path("outbox",
            "Folder of results waiting for the database; default "
            "postgres-outbox."),
       positive("outbox_quota_mb", "Largest size of the outbox, MB; the oldest go first.", 64)}};

  station = {
      "station",
      "A facet station: camera, PLC, recipes, stores and calibration.",
      {integer("schema_version", "Version of this format; 1.", 1, 1),
       text("name", "Station name, shown on the dashboard."),
       section("camera", "Where frames come from.", &camera, true),
       section("plc", "The line's PLC; without it facetd runs without a PLC link.", &plc),
       path("recipes", "Recipes folder, relative to the station file.", true),
       section("results", "Results store.", &results, true),
       section("archive", "Image archive.", &archive), section("http", "HTTP server.", &http),
       section("calibration", "Pixels to millimetres.", &calibration, true),
       section("mqtt", "Results to an MQTT broker.", &mqtt),
       section("postgres", "Results to a PostgreSQL database.", &postgres)}};
  station.fields[0].required = true;
}

const StationFormat& stationFormat() {
  static const StationFormat format;
  return format;
}

}  // namespace facet::config
