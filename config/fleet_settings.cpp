#include "config/fleet_settings.hpp"

#include <memory>
#include <stdexcept>
#include <string>

#include "config/libpq_library.hpp"
#include "config/yaml_document.hpp"

namespace facet::config {
namespace {

class SectionReader {
 public:
  SectionReader(const YAML::Node& node, const std::filesystem::path& file,
                const std::filesystem::path& base, Diagnostics& out)
      : node_(node), file_(file), base_(base), out_(out) {}

  std::string text(const char* key, std::string fallback) const {
    const YAML::Node n = node_[key];
    return n ? readString(n).value_or(fallback) : fallback;
  }
  long long integer(const char* key, long long fallback) const {
    const YAML::Node n = node_[key];
    return n ? readInteger(n).value_or(fallback) : fallback;
  }
  double number(const char* key, double fallback) const {
    const YAML::Node n = node_[key];
    return n ? readNumber(n).value_or(fallback) : fallback;
  }
  bool boolean(const char* key, bool fallback) const {
    const YAML::Node n = node_[key];
    return n ? readBoolean(n).value_or(fallback) : fallback;
  }
  // A file that must exist (TLS certificates): relative to the station file.
  std::filesystem::path existingFile(const YAML::Node& section, const char* key) {
    const YAML::Node n = section[key];
    if (!n || !n.IsScalar() || n.Scalar().empty()) return {};
    const auto p = (base_ / n.Scalar()).lexically_normal();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p, ec)) {
      // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "'" + std::string(key).
      std::string message = "'";
      message.append(key).append("' file '").append(n.Scalar()).append("' does not exist");
      error(n, std::move(message));
    }
    return p;
  }
  // The outbox folder: created by the sink, so only its parent must exist.
  OutboxSettings outbox(const std::string& fallbackName) {
    OutboxSettings s;
    const YAML::Node n = node_["outbox"];
    const std::string name = n && n.IsScalar() && !n.Scalar().empty() ? n.Scalar() : fallbackName;
    s.folder = (base_ / name).lexically_normal();
    if (!s.folder.has_filename()) s.folder = s.folder.parent_path();
    std::error_code ec;
    if (!std::filesystem::is_directory(s.folder.parent_path(), ec))
      error(n ? n : node_, "the folder containing the outbox (" + s.folder.parent_path().string() +
                               ") does not exist");
    s.quotaMb = number("outbox_quota_mb", s.quotaMb);
    return s;
  }
  void error(const YAML::Node& n, std::string message) {
    out_.error(locate(file_, n), std::move(message));
  }
  const YAML::Node& node() const { return node_; }

 private:
  const YAML::Node& node_;
  const std::filesystem::path& file_;
  const std::filesystem::path& base_;
  Diagnostics& out_;
};

// MQTT topic levels must not contain wildcards or separators.
bool validTopicLevel(const std::string& s) {
  return !s.empty() && s.find_first_of("/+#") == std::string::npos;
}

}  // namespace

MqttSettings readMqttSettings(const YAML::Node& node, const std::filesystem::path& file,
                              const std::filesystem::path& base, const std::string& station,
                              Diagnostics& out) {
  SectionReader r(node, file, base, out);
  MqttSettings s;
  s.enabled = true;
  s.host = r.text("host", s.host);
  s.topicPrefix = r.text("topic_prefix", s.topicPrefix);
  s.clientId = r.text("client_id", "facet-" + station);
  s.username = r.text("username", "");
  s.password = r.text("password", "");
  s.keepaliveS = static_cast<int>(r.integer("keepalive_s", s.keepaliveS));
  s.reconnectMaxMs = static_cast<int>(r.integer("reconnect_max_ms", s.reconnectMaxMs));
  if (const YAML::Node tls = node["tls"]; tls && tls.IsMap()) {
    s.caFile = r.existingFile(tls, "ca_file");
    s.certFile = r.existingFile(tls, "cert_file");
    s.keyFile = r.existingFile(tls, "key_file");
    s.tlsInsecure = tls["insecure"] ? readBoolean(tls["insecure"]).value_or(false) : false;
    if (s.certFile.empty() != s.keyFile.empty())
      r.error(tls,
              "tls needs both 'cert_file' and 'key_file' for a client certificate, or neither");
  }
  s.port = static_cast<int>(r.integer("port", s.caFile.empty() ? 1883 : 8883));
  if (!s.password.empty() && s.username.empty())
    r.error(node["password"], "'password' needs a 'username'");
  if (!validTopicLevel(station))
    r.error(node, "the station name '" + station +
                      "' cannot be an MQTT topic level (set 'name' without '/', '+' or '#')");
  for (const auto& level : [&] {
         std::vector<std::string> levels;
         std::string rest = s.topicPrefix;
         for (std::size_t slash; (slash = rest.find('/')) != std::string::npos;
              rest = rest.substr(slash + 1))
           levels.push_back(rest.substr(0, slash));
         levels.push_back(rest);
         return levels;
       }())
    if (!validTopicLevel(level)) {
      r.error(
          node["topic_prefix"] ? node["topic_prefix"] : node,
          "'topic_prefix' '" + s.topicPrefix + "' is not a topic: no empty level, no '+' or '#'");
      break;
    }
  s.outbox = r.outbox("mqtt-outbox");
  return s;
}

PostgresSettings readPostgresSettings(const YAML::Node& node, const std::filesystem::path& file,
                                      const std::filesystem::path& base, Diagnostics& out) {
  SectionReader r(node, file, base, out);
  PostgresSettings s;
  s.enabled = true;
  s.connection = r.text("connection", "");
  s.password = r.text("password", "");
  s.connectTimeoutS = static_cast<int>(r.integer("connect_timeout_s", s.connectTimeoutS));
  s.reconnectMaxMs = static_cast<int>(r.integer("reconnect_max_ms", s.reconnectMaxMs));
  s.batchParts = static_cast<int>(r.integer("batch_parts", s.batchParts));
  // libpq's own parser: a misspelt keyword is refused here, with its line, not at first connect.
  const YAML::Node& at = node["connection"] ? node["connection"] : node;
  try {
    const LibPq& pq = libpq();
    char* error = nullptr;
    std::unique_ptr<PQconninfoOption, decltype(LibPq::conninfoFree)> options(
        pq.conninfoParse(s.connection.c_str(), &error), pq.conninfoFree);
    if (!options) {
      std::string message = error ? error : "cannot be parsed";
      pq.freemem(error);
      while (!message.empty() && message.back() == '\n') message.pop_back();
      r.error(at, "'connection': " + message);
    }
  } catch (const std::runtime_error& e) {
    r.error(at, "'connection' cannot be checked: " + std::string(e.what()));
  }
  s.outbox = r.outbox("postgres-outbox");
  return s;
}

}  // namespace facet::config
