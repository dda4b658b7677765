#pragma once
// MosquittoBroker: Debian's `mosquitto` started by the test on 127.0.0.1 on a free port, with
// persistence in the test's folder (so that a restarted broker still knows the subscriber's
// session), killable and restartable. MqttSubscriber: an MQTT client of the test (libmosquitto,
// persistent session, QoS 1) that records every message it receives.

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tests/daemon/child_process.hpp"

struct mosquitto;

namespace facet::sinks_test {

class MosquittoBroker {
 public:
  // `passwords`: user -> password; empty = anonymous clients allowed.
  MosquittoBroker(std::string folder,
                  std::vector<std::pair<std::string, std::string>> passwords = {});
  ~MosquittoBroker();
  // A second listener on another free port that speaks TLS only, with the broker's certificate
  // and key; `clientCa` non-empty: clients must present a certificate it signed. Before start().
  void addTlsListener(const std::string& certFile, const std::string& keyFile,
                      const std::string& clientCa = "");
  // Starts the broker and waits until it accepts connections; throws when it does not.
  void start();
  // Writes the broker's sessions to disk now (SIGUSR1): a killed broker restarts from here.
  void saveSessions();
  void kill();                                            // SIGKILL: no goodbye, no final save
  void stop();                                            // SIGTERM
  [[nodiscard]] int port() const { return port_; }        // plain MQTT
  [[nodiscard]] int tlsPort() const { return tlsPort_; }  // 0: no TLS listener
  [[nodiscard]] bool running() const { return process_ != nullptr; }

 private:
  std::string folder_;
  int port_;
  int tlsPort_ = 0;
  std::unique_ptr<daemon_test::ChildProcess> process_;
};

struct MqttMessage {
  std::string topic;
  std::string payload;
  bool retained = false;
};

class MqttSubscriber {
 public:
  MqttSubscriber(std::string clientId, int port, std::string topic);
  ~MqttSubscriber();
  // Waits until the subscription is acknowledged.
  bool waitSubscribed(std::chrono::milliseconds timeout);
  // Subscriptions the broker confirmed so far: one more after each reconnection.
  int subscriptions() const;
  bool waitFor(const std::function<bool(const std::vector<MqttMessage>&)>& done,
               std::chrono::milliseconds timeout);
  [[nodiscard]] std::vector<MqttMessage> messages() const;

 private:
  mosquitto* mosq_ = nullptr;
  std::string topic_;
  mutable std::mutex mutex_;
  std::vector<MqttMessage> messages_;
  bool subscribed_ = false;
  int subscriptions_ = 0;
};

}  // namespace facet::sinks_test
