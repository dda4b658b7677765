#pragma once
// MqttPublisher: each part's result on <prefix>/<station>/result (QoS 1), the station's status
// retained on <prefix>/<station>/status ("online"; the broker's last will says "offline").
//
// submit() only appends the part to the outbox on disk and returns: a broker that is down, slow
// or refusing us never holds up inspection or the PLC. A thread of its own connects (with
// back-off), publishes the outbox oldest first with one message in flight, and deletes a record
// once the broker has acknowledged it (PUBACK). Delivery is at least once and in order: a
// message whose PUBACK was lost with the connection is sent again after reconnecting.

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "config/fleet_settings.hpp"
#include "service/engine/part_result.hpp"
#include "service/sinks/outbox.hpp"
#include "service/sinks/sink_status.hpp"

struct mosquitto;

namespace facet::service {

class MqttPublisher {
 public:
  // Opens the outbox (throws std::runtime_error when its folder cannot be made). Does not
  // connect yet.
  MqttPublisher(config::MqttSettings settings, std::string station);
  ~MqttPublisher();
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  void start();
  // Never blocks on the broker: the part goes to the outbox.
  void submit(const PartResult& part);
  // Sends what is left for at most `flush`, publishes "offline", disconnects.
  void stop(std::chrono::milliseconds flush = std::chrono::milliseconds(2000));

  [[nodiscard]] SinkStatus status() const;
  [[nodiscard]] std::string resultTopic() const { return prefix_ + "/result"; }
  [[nodiscard]] std::string statusTopic() const { return prefix_ + "/status"; }

 private:
  void run();
  void connected(int rc);
  void published(int mid);
  void setError(std::string error);
  // libmosquitto's error text for `rc`, with OpenSSL's reason when TLS failed.
  std::string failure(int rc);

  config::MqttSettings settings_;
  std::string station_;
  std::string prefix_;  // <topic_prefix>/<station>
  Outbox outbox_;
  mosquitto* mosq_ = nullptr;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  std::chrono::steady_clock::time_point flushDeadline_;

  // Owned by the sending thread (callbacks run on it, inside mosquitto_loop).
  // The one result sent and not yet confirmed. It survives a lost connection: libmosquitto keeps
  // it and sends it again (same message id) after reconnecting, so sending it anew as well would
  // deliver it twice.
  struct InFlight {
    int mid;
    std::uint64_t seq;
    std::chrono::steady_clock::time_point since;  // sent, or the connection came back
  };
  std::optional<InFlight> inFlight_;
  std::optional<int> offlineMid_;  // the goodbye status message, at stop
  bool offlineAcked_ = false;
  std::string tlsError_;  // OpenSSL's last error as libmosquitto logged it

  mutable std::mutex statusMutex_;
  SinkStatus status_;
};

}  // namespace facet::service
