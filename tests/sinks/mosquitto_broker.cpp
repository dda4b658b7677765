#include "tests/sinks/mosquitto_broker.hpp"

#include <mosquitto.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <csignal>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "tests/plc/pymodbus_peer.hpp"

namespace facet::sinks_test {
namespace {

using namespace std::chrono_literals;

bool accepts(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
  ::close(fd);
  return ok;
}

}  // namespace

MosquittoBroker::MosquittoBroker(std::string folder,
                                 std::vector<std::pair<std::string, std::string>> passwords)
    : folder_(std::move(folder)), port_(plc::test::freeTcpPort()) {
  std::ofstream conf(folder_ + "/mosquitto.conf");
  conf << "listener " << port_
       << " 127.0.0.1\n"
       // Persistent sessions survive a restart. The database is written when the test asks
       // (saveSessions()) and at a clean stop, not periodically: a killed broker comes back with
       // the state of the last save. (Saving after every change would make a killed broker
       // replay its own stale in-flight messages to subscribers, which then see repeats that
       // no publisher sent: QoS 1 from a crashed broker is at least once.)
       << "persistence true\npersistence_location " << folder_ << "/\nautosave_interval 0\n"
       << "log_dest file " << folder_ << "/mosquitto.log\n";
  // As root mosquitto would switch to its own user, which cannot write the test's folder.
  if (::geteuid() == 0) conf << "user root\n";
  if (passwords.empty()) {
    conf << "allow_anonymous true\n";
  } else {
    conf << "allow_anonymous false\npassword_file " << folder_ << "/passwords\n";
    std::ofstream(folder_ + "/passwords").close();
    for (const auto& [user, password] : passwords) {
      const std::string cmd =
          "mosquitto_passwd -b " + folder_ + "/passwords " + user + " " + password + " 2>/dev/null";
      if (std::system(cmd.c_str()) != 0) throw std::runtime_error("mosquitto_passwd failed");
    }
  }
}

void MosquittoBroker::addTlsListener(const std::string& certFile, const std::string& keyFile,
                                     const std::string& clientCa) {
  tlsPort_ = plc::test::freeTcpPort();
  std::ofstream conf(folder_ + "/mosquitto.conf", std::ios::app);
  conf << "listener " << tlsPort_ << " 127.0.0.1\ncertfile " << certFile << "\nkeyfile " << keyFile
       << "\n";
  if (!clientCa.empty()) conf << "cafile " << clientCa << "\nrequire_certificate true\n";
}

MosquittoBroker::~MosquittoBroker() {
  process_.reset();
}

void MosquittoBroker::start() {
  if (::access("/usr/sbin/mosquitto", X_OK) != 0)
    throw std::runtime_error(
        "/usr/sbin/mosquitto is missing: install the Debian package mosquitto "
        "(deploy/install-deps.sh)");
  process_ = std::make_unique<daemon_test::ChildProcess>(
      std::vector<std::string>{"/usr/sbin/mosquitto", "-c", folder_ + "/mosquitto.conf"},
      std::map<std::string, std::string>{}, folder_ + "/mosquitto.stderr");
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < until) {
    if (accepts(port_) && (tlsPort_ == 0 || accepts(tlsPort_))) return;
    if (process_->wait(0ms)) break;
    std::this_thread::sleep_for(20ms);
  }
  throw std::runtime_error("mosquitto did not start on port " + std::to_string(port_) + "\n" +
                           process_->outputTail());
}

void MosquittoBroker::saveSessions() {
  if (!process_) return;
  const auto db = std::filesystem::path(folder_) / "mosquitto.db";
  std::error_code ec;
  const auto before = std::filesystem::last_write_time(db, ec);
  process_->signal(SIGUSR1);  // mosquitto writes its persistence database
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (std::chrono::steady_clock::now() < until) {
    const auto now = std::filesystem::last_write_time(db, ec);
    if (!ec && now != before) return;
    std::this_thread::sleep_for(10ms);
  }
  throw std::runtime_error("mosquitto did not write " + db.string());
}

void MosquittoBroker::kill() {
  if (!process_) return;
  process_->signal(SIGKILL);
  process_->wait(5s);
  process_.reset();
}

void MosquittoBroker::stop() {
  if (!process_) return;
  process_->signal(SIGTERM);
  process_->wait(5s);
  process_.reset();
}

MqttSubscriber::MqttSubscriber(std::string clientId, int port, std::string topic)
    : topic_(std::move(topic)) {
  mosquitto_lib_init();
  // A persistent session (clean_session false) at QoS 1: what is published while this client is
  // reconnecting after a broker restart is kept for it.
  mosq_ = mosquitto_new(clientId.c_str(), false, this);
  mosquitto_connect_callback_set(mosq_, [](mosquitto* m, void* obj, int rc) {
    if (rc == 0)
      mosquitto_subscribe(m, nullptr, static_cast<MqttSubscriber*>(obj)->topic_.c_str(), 1);
  });
  mosquitto_subscribe_callback_set(mosq_, [](mosquitto*, void* obj, int, int, const int*) {
    auto* self = static_cast<MqttSubscriber*>(obj);
    std::lock_guard lock(self->mutex_);
    self->subscribed_ = true;
    ++self->subscriptions_;
  });
  mosquitto_message_callback_set(mosq_, [](mosquitto*, void* obj, const mosquitto_message* m) {
    auto* self = static_cast<MqttSubscriber*>(obj);
    std::lock_guard lock(self->mutex_);
    self->messages_.push_back(
        {m->topic, std::string(static_cast<const char*>(m->payload), m->payloadlen), m->retain});
  });
  mosquitto_reconnect_delay_set(mosq_, 1, 1, false);
  mosquitto_connect(mosq_, "127.0.0.1", port, 10);
  mosquitto_loop_start(mosq_);
}

MqttSubscriber::~MqttSubscriber() {
  mosquitto_disconnect(mosq_);
  mosquitto_loop_stop(mosq_, true);
  mosquitto_destroy(mosq_);
}

bool MqttSubscriber::waitSubscribed(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    {
      std::lock_guard lock(mutex_);
      if (subscribed_) return true;
    }
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

bool MqttSubscriber::waitFor(const std::function<bool(const std::vector<MqttMessage>&)>& done,
                             std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (done(messages())) return true;
    std::this_thread::sleep_for(20ms);
  }
  return done(messages());
}

int MqttSubscriber::subscriptions() const {
  std::lock_guard lock(mutex_);
  return subscriptions_;
}

std::vector<MqttMessage> MqttSubscriber::messages() const {
  std::lock_guard lock(mutex_);
  return messages_;
}

}  // namespace facet::sinks_test
