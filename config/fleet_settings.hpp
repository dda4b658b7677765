#pragma once
// Where a station sends its results beyond its own SQLite file: an MQTT broker and a central
// PostgreSQL database (the `mqtt` and `postgres` sections of the station file). Both are
// optional; each keeps the results it could not deliver yet in an outbox folder on disk.

#include <cstdint>
#include <filesystem>
#include <string>

#include <yaml-cpp/yaml.h>

#include "config/diagnostic.hpp"

namespace facet::config {

// Results waiting for a sink: one file per part in `folder`, oldest first. When `quotaMb` is
// reached the oldest are dropped (counted and logged): inspection never waits for a sink.
struct OutboxSettings {
  std::filesystem::path folder;  // absolute
  double quotaMb = 64.0;
};

struct MqttSettings {
  bool enabled = false;  // the station file has an mqtt section
  std::string host = "127.0.0.1";
  int port = 1883;
  std::string clientId;               // default: "facet-<station>"
  std::string topicPrefix = "facet";  // topics <prefix>/<station>/result and .../status
  std::string username;               // empty: no user name
  std::string password;
  int keepaliveS = 30;
  int reconnectMaxMs = 5000;
  // TLS: on when caFile is set. certFile/keyFile: client certificate (both or neither).
  std::filesystem::path caFile, certFile, keyFile;
  bool tlsInsecure = false;  // do not check the broker's host name (test brokers only)
  OutboxSettings outbox;
};

struct PostgresSettings {
  bool enabled = false;    // the station file has a postgres section
  std::string connection;  // libpq connection string ("host=... dbname=... user=...")
  std::string password;    // kept apart from the connection string; empty: libpq's own sources
  int connectTimeoutS = 5;
  int reconnectMaxMs = 5000;
  int batchParts = 50;  // parts written per transaction when catching up
  OutboxSettings outbox;
};

// Readers for the two sections, after validateObject() checked keys and types. `base` is the
// station file's folder (outbox folders and TLS files are relative to it), `station` its name.
MqttSettings readMqttSettings(const YAML::Node& node, const std::filesystem::path& file,
                              const std::filesystem::path& base, const std::string& station,
                              Diagnostics& out);
PostgresSettings readPostgresSettings(const YAML::Node& node, const std::filesystem::path& file,
                                      const std::filesystem::path& base, Diagnostics& out);

}  // namespace facet::config
