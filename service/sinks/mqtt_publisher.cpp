#include "service/sinks/mqtt_publisher.hpp"

#include <mosquitto.h>

#include <cerrno>
#include <cstring>
#include <mutex>

#include <spdlog/spdlog.h>

#include "service/sinks/fleet_message.hpp"

namespace facet::service {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr const char* kOnline = "online";
constexpr const char* kOffline = "offline";
// A broker that accepted the TCP connection but has not answered CONNECT within this is dropped.
constexpr auto kConnackTimeout = 10s;
// A result unconfirmed this long on a live connection is sent again (at least once): a broker
// that lost it without closing the connection would otherwise hold the outbox up for good.
constexpr auto kPubackTimeout = 10s;

std::string errorText(int rc) {
  return rc == MOSQ_ERR_ERRNO ? std::strerror(errno) : mosquitto_strerror(rc);
}

MqttPublisher* self(void* obj) {
  return static_cast<MqttPublisher*>(obj);
}

}  // namespace

MqttPublisher::MqttPublisher(config::MqttSettings settings, std::string station)
    : settings_(std::move(settings)),
      station_(std::move(station)),
      prefix_(settings_.topicPrefix + "/" + station_),
      outbox_(settings_.outbox.folder,
              static_cast<std::uint64_t>(settings_.outbox.quotaMb * 1024 * 1024), "mqtt outbox") {
  static std::once_flag libraryInit;
  std::call_once(libraryInit, [] { mosquitto_lib_init(); });
  status_.name = "mqtt";
  status_.peer = settings_.host + ":" + std::to_string(settings_.port);
  status_.lastError = "not connected yet";
  mosq_ = mosquitto_new(settings_.clientId.c_str(), true, this);
  if (!mosq_)
    throw std::runtime_error("mqtt: cannot create a client: " + errorText(MOSQ_ERR_ERRNO));
  mosquitto_int_option(mosq_, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
  const std::string statusTopic = this->statusTopic();
  mosquitto_will_set(mosq_, statusTopic.c_str(), static_cast<int>(std::strlen(kOffline)), kOffline,
                     1, true);
  if (!settings_.username.empty())
    mosquitto_username_pw_set(mosq_, settings_.username.c_str(),
                              settings_.password.empty() ? nullptr : settings_.password.c_str());
  if (!settings_.caFile.empty()) {
    const int rc =
        mosquitto_tls_set(mosq_, settings_.caFile.c_str(), nullptr,
                          settings_.certFile.empty() ? nullptr : settings_.certFile.c_str(),
                          settings_.keyFile.empty() ? nullptr : settings_.keyFile.c_str(), nullptr);
    if (rc != MOSQ_ERR_SUCCESS) {
      mosquitto_destroy(mosq_);
      throw std::runtime_error("mqtt tls: " + errorText(rc));
    }
    mosquitto_tls_insecure_set(mosq_, settings_.tlsInsecure);
  }
  mosquitto_log_callback_set(mosq_, [](mosquitto*, void* obj, int level, const char* text) {
    if ((level & MOSQ_LOG_ERR) && std::strncmp(text, "OpenSSL Error", 13) == 0)
      self(obj)->tlsError_ = text;
  });
  mosquitto_connect_callback_set(mosq_,
                                 [](mosquitto*, void* obj, int rc) { self(obj)->connected(rc); });
  mosquitto_publish_callback_set(mosq_,
                                 [](mosquitto*, void* obj, int mid) { self(obj)->published(mid); });
}

MqttPublisher::~MqttPublisher() {
  stop(0ms);
  mosquitto_destroy(mosq_);
}

void MqttPublisher::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
}

void MqttPublisher::submit(const PartResult& part) {
  outbox_.append(fleetMessage(station_, part).dump());
}

void MqttPublisher::stop(std::chrono::milliseconds flush) {
  if (!thread_.joinable()) return;
  flushDeadline_ = Clock::now() + flush;
  stopping_ = true;
  thread_.join();
}

SinkStatus MqttPublisher::status() const {
  std::lock_guard lock(statusMutex_);
  SinkStatus s = status_;
  s.outbox = outbox_.stats();
  return s;
}

void MqttPublisher::setError(std::string error) {
  std::lock_guard lock(statusMutex_);
  if (error != status_.lastError)
    spdlog::warn("mqtt {}: {} (results wait in {})", status_.peer, error,
                 outbox_.folder().string());
  status_.lastError = std::move(error);
  status_.connected = false;
}

std::string MqttPublisher::failure(int rc) {
  std::string text = errorText(rc);
  if (settings_.caFile.empty() || tlsError_.empty()) return text;
  // libmosquitto says only "A TLS error occurred" (or, when the broker rejects the client's
  // certificate after the handshake, "connection lost"); OpenSSL's reason is in its log.
  text += " (tls: " + tlsError_ +
          "; check mqtt.tls.ca_file signed the broker's certificate, the broker's certificate "
          "names mqtt.host, and mqtt.tls.cert_file / key_file if the broker asks for one)";
  tlsError_.clear();
  return text;
}

void MqttPublisher::connected(int rc) {
  if (rc != 0) {
    // Refused: wrong credentials, not authorised, bad client id. Retried with back-off, since an
    // administrator may fix the broker's side; the station stays degraded meanwhile.
    setError(std::string("broker refused the connection: ") + mosquitto_connack_string(rc) +
             (rc == 4 || rc == 5 ? " (check mqtt.username and mqtt.password)" : ""));
    return;
  }
  mosquitto_publish(mosq_, nullptr, statusTopic().c_str(), static_cast<int>(std::strlen(kOnline)),
                    kOnline, 1, true);
  if (inFlight_) inFlight_->since = Clock::now();  // libmosquitto sends it again now
  std::lock_guard lock(statusMutex_);
  status_.connected = true;
  status_.lastError.clear();
  ++status_.connects;
  spdlog::info("mqtt {}: connected; {} results waiting", status_.peer, outbox_.stats().pending);
}

void MqttPublisher::published(int mid) {
  if (offlineMid_ && mid == *offlineMid_) offlineAcked_ = true;
  if (!inFlight_ || inFlight_->mid != mid) return;
  outbox_.remove({inFlight_->seq});
  inFlight_.reset();
  std::lock_guard lock(statusMutex_);
  ++status_.delivered;
}

void MqttPublisher::run() {
  bool socketOpen = false, everConnected = false;
  auto backoff = 100ms;
  auto nextAttempt = Clock::now();
  auto attemptStarted = Clock::now();
  auto isConnected = [this] {
    std::lock_guard lock(statusMutex_);
    return status_.connected;
  };
  auto lose = [&](const std::string& why) {
    socketOpen = false;  // inFlight_ stays: libmosquitto sends it again after reconnecting
    setError(why);
    nextAttempt = Clock::now() + backoff;
    backoff = std::min<std::chrono::milliseconds>(
        backoff * 2, std::chrono::milliseconds(settings_.reconnectMaxMs));
  };
  while (true) {
    if (stopping_) {
      const bool empty = outbox_.stats().pending == 0 && !inFlight_;
      if (empty || !socketOpen || Clock::now() >= flushDeadline_) break;
    }
    if (!socketOpen) {
      if (Clock::now() < nextAttempt) {
        outbox_.waitForRecords(20ms);
        if (!stopping_) std::this_thread::sleep_until(std::min(nextAttempt, Clock::now() + 50ms));
        continue;
      }
      const int rc = everConnected ? mosquitto_reconnect_async(mosq_)
                                   : mosquitto_connect_async(mosq_, settings_.host.c_str(),
                                                             settings_.port, settings_.keepaliveS);
      if (rc != MOSQ_ERR_SUCCESS) {
        lose("cannot connect: " + failure(rc));
        continue;
      }
      everConnected = true;  // from now on reconnect_async reuses host, port and keep-alive
      socketOpen = true;
      attemptStarted = Clock::now();
    }
    const bool up = isConnected();
    if (up) backoff = 100ms;
    if (up && inFlight_ && Clock::now() - inFlight_->since > kPubackTimeout) {
      spdlog::warn("mqtt {}: result {} not confirmed within {} s; sending it again", settings_.host,
                   inFlight_->seq, kPubackTimeout.count());
      inFlight_.reset();
    }
    if (up && !inFlight_) {
      const auto next = outbox_.peek(1);
      if (!next.empty()) {
        int mid = 0;
        const auto& payload = next.front().payload;
        const int rc =
            mosquitto_publish(mosq_, &mid, resultTopic().c_str(), static_cast<int>(payload.size()),
                              payload.data(), 1, false);
        if (rc == MOSQ_ERR_SUCCESS)
          inFlight_ = InFlight{mid, next.front().seq, Clock::now()};
        else if (rc == MOSQ_ERR_PAYLOAD_SIZE) {
          spdlog::error("mqtt: result too large for the broker ({} bytes); dropped",
                        payload.size());
          outbox_.remove({next.front().seq});
        }
      }
    }
    const int rc = mosquitto_loop(mosq_, up && !inFlight_ ? 5 : 20, 1);
    if (rc != MOSQ_ERR_SUCCESS) {
      std::string why;
      {
        std::lock_guard lock(statusMutex_);
        why = status_.lastError;  // a refusal explains itself better than "connection lost"
      }
      lose(!isConnected() && why.starts_with("broker refused") ? why
                                                               : "connection lost: " + failure(rc));
      continue;
    }
    if (!isConnected() && Clock::now() - attemptStarted > kConnackTimeout) {
      mosquitto_disconnect(mosq_);
      lose("no answer from the broker within 10 s");
    }
  }
  if (socketOpen && isConnected()) {
    // A clean goodbye: the retained status says offline (the will is for crashes only).
    int mid = 0;
    if (mosquitto_publish(mosq_, &mid, statusTopic().c_str(),
                          static_cast<int>(std::strlen(kOffline)), kOffline, 1,
                          true) == MOSQ_ERR_SUCCESS) {
      offlineMid_ = mid;
      const auto until = Clock::now() + 1s;
      while (!offlineAcked_ && Clock::now() < until &&
             mosquitto_loop(mosq_, 20, 1) == MOSQ_ERR_SUCCESS) {
      }
    }
    mosquitto_disconnect(mosq_);
    mosquitto_loop(mosq_, 10, 1);
  }
  std::lock_guard lock(statusMutex_);
  status_.connected = false;
  status_.lastError = "stopped";
}

}  // namespace facet::service
