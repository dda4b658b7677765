// MqttPublisher against Debian's mosquitto broker, started by the test on 127.0.0.1.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <thread>

#include <nlohmann/json.hpp>

#include "service/sinks/mqtt_publisher.hpp"
#include "tests/sinks/mosquitto_broker.hpp"
#include "tests/sinks/sample_part.hpp"
#include "tests/sinks/test_certificates.hpp"

namespace facet::sinks_test {
namespace {

using namespace std::chrono_literals;
using service::MqttPublisher;

config::MqttSettings settingsFor(const MosquittoBroker& broker, const std::string& folder) {
  config::MqttSettings s;
  s.enabled = true;
  s.port = broker.port();
  s.clientId = "facet-test-station";
  s.reconnectMaxMs = 400;
  s.keepaliveS = 5;
  s.outbox.folder = folder + "/outbox";
  return s;
}

std::vector<std::uint64_t> partIds(const std::vector<MqttMessage>& messages) {
  std::vector<std::uint64_t> ids;
  for (const auto& m : messages)
    if (m.topic.ends_with("/result"))
      ids.push_back(nlohmann::json::parse(m.payload).at("part_id").get<std::uint64_t>());
  return ids;
}

bool waitUntil(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

TEST(MqttPublisher, ResultCarriesStationRecipeValuesAndLimitsAndStatusIsRetained) {
  daemon_test::TempDir dir;
  MosquittoBroker broker(dir.path());
  broker.start();
  MqttSubscriber results("test-results", broker.port(), "facet/cam1/result");
  ASSERT_TRUE(results.waitSubscribed(5s));
  MqttPublisher publisher(settingsFor(broker, dir.path()), "cam1");
  publisher.start();
  publisher.submit(samplePart(7));
  ASSERT_TRUE(results.waitFor([](const auto& m) { return m.size() == 1; }, 10s));
  const auto message = nlohmann::json::parse(results.messages().front().payload);
  EXPECT_EQ(message["station"], "cam1");
  EXPECT_EQ(message["part_id"], 7);
  EXPECT_EQ(message["recipe"], "flange");
  EXPECT_EQ(message["recipe_id"], 3);
  EXPECT_EQ(message["recipe_version"], "9c1e55aa");
  EXPECT_EQ(message["verdict"], "fail");
  EXPECT_EQ(message["failed_checks"], nlohmann::json::array({"bore.diameter"}));
  EXPECT_EQ(message["time_us"], 1795986187125331LL + 7000);
  EXPECT_EQ(message["time"], "2026-11-29T21:03:07.132Z");
  const auto& d = message["values"]["bore.diameter"];
  EXPECT_EQ(d["unit"], "mm");
  EXPECT_DOUBLE_EQ(d["value"].get<double>(), 12.07);
  EXPECT_DOUBLE_EQ(d["lower"].get<double>(), 11.95);
  EXPECT_DOUBLE_EQ(d["upper"].get<double>(), 12.04);
  EXPECT_EQ(d["pass"], false);
  EXPECT_EQ(message["values"]["locate.score"]["unit"], "score");
  EXPECT_FALSE(message["values"]["locate.score"].contains("lower"));

  // A client arriving later gets the retained status at once.
  MqttSubscriber late("test-status", broker.port(), "facet/cam1/status");
  ASSERT_TRUE(late.waitFor([](const auto& m) { return !m.empty(); }, 5s));
  EXPECT_EQ(late.messages().front().payload, "online");
  EXPECT_TRUE(late.messages().front().retained);
  publisher.stop();
  ASSERT_TRUE(late.waitFor([](const auto& m) { return m.size() == 2; }, 5s));
  EXPECT_EQ(late.messages().back().payload, "offline");
  EXPECT_EQ(publisher.status().delivered, 1u);
}

// The run: 1,000 parts, the broker killed (SIGKILL) and restarted twice while they are
// produced; a subscriber must see every part id, in order, none lost; the only repeat allowed
// is QoS 1's: the message in flight at the kill, once per outage.
TEST(MqttPublisher, BrokerKilledTwiceDuringThousandPartsLosesNothingAndKeepsOrder) {
  daemon_test::TempDir dir;
  MosquittoBroker broker(dir.path());
  broker.start();
  MqttSubscriber subscriber("test-line", broker.port(), "facet/cam1/result");
  ASSERT_TRUE(subscriber.waitSubscribed(5s));
  // The subscriber's persistent session is on disk: the killed broker comes back with it, and
  // keeps for it what is published before it has reconnected.
  broker.saveSessions();
  MqttPublisher publisher(settingsFor(broker, dir.path()), "cam1");
  publisher.start();
  ASSERT_TRUE(waitUntil([&] { return publisher.status().connected; }, 10s));

  constexpr int kParts = 1000;
  struct Outage {
    int killAt, restartAt;
    std::uint64_t confirmedAtKill = 0;  // parts 1..this the broker had acknowledged
    std::uint64_t bufferedAtRestart = 0;
    double recoverMs = -1;  // -1: still catching up when the run went on
  };
  std::vector<Outage> outages{{250, 400}, {600, 750}};
  std::optional<std::chrono::steady_clock::time_point> restartedAt;
  Outage* recovering = nullptr;
  std::vector<double> submitUs;
  for (int i = 1; i <= kParts; ++i) {
    // Caught up: everything buffered during the outage has been confirmed by the broker.
    if (recovering && publisher.status().outbox.pending == 0) {
      recovering->recoverMs =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - *restartedAt)
              .count();
      recovering = nullptr;
    }
    for (auto& o : outages) {
      if (i == o.killAt) {
        broker.kill();
        // What the broker acknowledged before it died: read once the publisher has seen the loss
        // (a PUBACK still in the socket is read before that).
        ASSERT_TRUE(waitUntil([&] { return !publisher.status().connected; }, 5s));
        o.confirmedAtKill = publisher.status().delivered;
      }
      if (i == o.restartAt) {
        o.bufferedAtRestart = publisher.status().outbox.pending;
        const int subscriptions = subscriber.subscriptions();
        broker.start();
        restartedAt = std::chrono::steady_clock::now();
        recovering = &o;
        // The line's subscriber must be back before the next kill: what the broker queues for an
        // absent subscriber lives in its memory, and dies with it.
        ASSERT_TRUE(waitUntil([&] { return subscriber.subscriptions() > subscriptions; }, 10s));
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    publisher.submit(samplePart(static_cast<std::uint64_t>(i)));
    submitUs.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    std::this_thread::sleep_for(2ms);
  }
  // The publisher is done when the broker has acknowledged every part.
  ASSERT_TRUE(waitUntil([&] { return publisher.status().delivered >= kParts; }, 60s))
      << "the broker acknowledged " << publisher.status().delivered << " of " << kParts;
  std::this_thread::sleep_for(500ms);  // the last messages, and a duplicate, would arrive now
  // QoS 1 is at least once: the one message in flight when the broker died (sent, forwarded,
  // its PUBACK lost with the broker) is sent again after the restart; nothing else may repeat.
  // First arrivals are in order, and a repeat is the previous message again.
  const auto ids = partIds(subscriber.messages());
  std::vector<std::uint64_t> first;
  std::size_t repeats = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (!first.empty() && ids[i] <= first.back()) {
      ++repeats;
      EXPECT_EQ(ids[i], first.back()) << "a repeat that is not the message in flight, at " << i;
      continue;
    }
    first.push_back(ids[i]);
  }
  EXPECT_LE(repeats, outages.size());
  // Every part arrives, but for one the broker itself lost: killed right after acknowledging a
  // message and before forwarding it (mosquitto keeps messages in memory; its persistence file is
  // written from time to time, not before each PUBACK). Such a part is the last one, or the one
  // before, that the broker confirmed before the kill; the publisher cannot know of it and must
  // not be blamed for it, and any other gap is the publisher's.
  std::size_t lostInBroker = 0;
  for (std::uint64_t id = 1, k = 0; id <= kParts; ++id) {
    if (k < first.size() && first[k] == id) {
      ++k;
      continue;
    }
    const bool atAKill = std::any_of(outages.begin(), outages.end(), [&](const Outage& o) {
      return id + 1 >= o.confirmedAtKill && id <= o.confirmedAtKill;
    });
    EXPECT_TRUE(atAKill) << "part " << id << " never arrived";
    ++lostInBroker;
  }
  EXPECT_LE(lostInBroker, outages.size());
  std::printf(
      "%zu parts arrived exactly once, %zu twice (in flight when the broker was killed), %zu "
      "lost inside the killed broker after it had acknowledged them\n",
      first.size() - repeats, repeats, lostInBroker);
  const auto status = publisher.status();
  EXPECT_EQ(status.outbox.dropped, 0u);
  EXPECT_EQ(status.outbox.pending, 0u);
  EXPECT_GE(status.connects, 3u);
  for (const auto& o : outages) {
    EXPECT_GT(o.bufferedAtRestart, 0u);
    std::printf("outage parts %d-%d: %llu parts buffered on disk; %s\n", o.killAt, o.restartAt,
                static_cast<unsigned long long>(o.bufferedAtRestart),
                o.recoverMs < 0 ? "still catching up when the next outage began"
                                : ("caught up " + std::to_string(static_cast<int>(o.recoverMs)) +
                                   " ms after the broker restarted")
                                      .c_str());
  }
  std::sort(submitUs.begin(), submitUs.end());
  std::printf("submit() per part: median %.0f us, p99 %.0f us, max %.0f us\n",
              submitUs[submitUs.size() / 2], submitUs[submitUs.size() * 99 / 100], submitUs.back());
}

TEST(MqttPublisher, BrokerDownAtStartBuffersAndDeliversInOrderOnceItIsUp) {
  daemon_test::TempDir dir;
  MosquittoBroker broker(dir.path());
  broker.start();
  {
    // The line's subscriber has a persistent session at the broker before the outage.
    MqttSubscriber early("test-line", broker.port(), "facet/cam1/result");
    ASSERT_TRUE(early.waitSubscribed(5s));
  }
  broker.stop();
  MqttPublisher publisher(settingsFor(broker, dir.path()), "cam1");
  publisher.start();
  for (std::uint64_t i = 1; i <= 20; ++i) publisher.submit(samplePart(i));
  ASSERT_TRUE(waitUntil(
      [&] {
        return !publisher.status().lastError.empty() &&
               publisher.status().lastError != "not connected yet";
      },
      5s));
  const auto down = publisher.status();
  EXPECT_TRUE(down.degraded());
  EXPECT_NE(down.lastError.find("refused"), std::string::npos) << down.lastError;
  EXPECT_EQ(down.outbox.pending, 20u);
  broker.start();
  MqttSubscriber subscriber("test-line", broker.port(), "facet/cam1/result");
  ASSERT_TRUE(subscriber.waitFor([](const auto& m) { return partIds(m).size() >= 20; }, 20s));
  const auto ids = partIds(subscriber.messages());
  ASSERT_EQ(ids.size(), 20u);
  for (std::size_t i = 0; i < ids.size(); ++i) EXPECT_EQ(ids[i], i + 1);
  EXPECT_FALSE(publisher.status().degraded());
}

TEST(MqttPublisher, WrongPasswordIsAClearErrorAndKeepsTheResults) {
  daemon_test::TempDir dir;
  MosquittoBroker broker(dir.path(), {{"station", "right-password"}});
  broker.start();
  auto settings = settingsFor(broker, dir.path());
  settings.username = "station";
  settings.password = "wrong-password";
  MqttPublisher publisher(settings, "cam1");
  publisher.start();
  publisher.submit(samplePart(1));
  ASSERT_TRUE(
      waitUntil([&] { return publisher.status().lastError.starts_with("broker refused"); }, 10s))
      << publisher.status().lastError;
  const auto s = publisher.status();
  EXPECT_TRUE(s.degraded());
  EXPECT_NE(s.lastError.find("mqtt.password"), std::string::npos) << s.lastError;
  EXPECT_EQ(s.outbox.pending, 1u);
  EXPECT_EQ(s.delivered, 0u);
}

TEST(MqttPublisher, FullQuotaDropsTheOldestAndTheRestFollowInOrder) {
  daemon_test::TempDir dir;
  MosquittoBroker broker(dir.path());
  broker.start();
  {
    MqttSubscriber early("test-line", broker.port(), "facet/cam1/result");
    ASSERT_TRUE(early.waitSubscribed(5s));
  }
  broker.stop();
  auto settings = settingsFor(broker, dir.path());
  settings.outbox.quotaMb = 20.0 / 1024;  // 20 KB: a few dozen results
  MqttPublisher publisher(settings, "cam1");
  publisher.start();
  constexpr std::uint64_t kParts = 300;
  for (std::uint64_t i = 1; i <= kParts; ++i) publisher.submit(samplePart(i));
  const auto full = publisher.status();
  EXPECT_GT(full.outbox.dropped, 0u);
  EXPECT_LE(full.outbox.bytes, 20u * 1024);
  EXPECT_EQ(full.outbox.dropped + full.outbox.pending, kParts);
  broker.start();
  MqttSubscriber subscriber("test-line", broker.port(), "facet/cam1/result");
  ASSERT_TRUE(subscriber.waitFor(
      [&](const auto& m) { return partIds(m).size() >= full.outbox.pending; }, 20s));
  const auto ids = partIds(subscriber.messages());
  ASSERT_EQ(ids.size(), full.outbox.pending);
  // The newest survive, in order.
  for (std::size_t i = 0; i < ids.size(); ++i) EXPECT_EQ(ids[i], full.outbox.dropped + 1 + i);
}

// The station's settings for the broker's TLS listener, checking its certificate with `caFile`.
config::MqttSettings tlsSettingsFor(const MosquittoBroker& broker, const std::string& folder,
                                    const std::string& caFile) {
  auto settings = settingsFor(broker, folder);
  settings.port = broker.tlsPort();
  settings.caFile = caFile;
  return settings;
}

// A station the broker's TLS listener does not let in: the part stays in its outbox, the error
// names TLS. Returns the error.
std::string refusedOverTls(config::MqttSettings settings, const std::string& folder) {
  settings.clientId = "facet-test-refused";
  settings.outbox.folder = folder + "/outbox-refused";
  MqttPublisher refused(settings, "cam2");
  refused.start();
  refused.submit(samplePart(1));
  EXPECT_TRUE(
      waitUntil([&] { return refused.status().lastError.find("tls") != std::string::npos; }, 10s))
      << refused.status().lastError;
  const auto s = refused.status();
  EXPECT_TRUE(s.degraded());
  EXPECT_EQ(s.outbox.pending, 1u);
  EXPECT_EQ(s.delivered, 0u);
  return s.lastError;
}

// A station that gets in: part `id` reaches the test's subscriber.
void deliveredOverTls(const config::MqttSettings& settings, MqttSubscriber& results,
                      std::uint64_t id) {
  MqttPublisher publisher(settings, "cam1");
  publisher.start();
  publisher.submit(samplePart(id));
  ASSERT_TRUE(results.waitFor([](const auto& m) { return partIds(m).size() == 1; }, 10s))
      << publisher.status().lastError;
  EXPECT_EQ(partIds(results.messages()).front(), id);
}

// TLS: the broker has a TLS listener beside its plain one; the test's subscriber reads on the
// plain one what the station sent over TLS.
TEST(MqttPublisherTls, TheStationsCaAndTheBrokersNameCheckedDeliversOverTls) {
  daemon_test::TempDir dir;
  const TestCertificates certificates(dir.path());
  MosquittoBroker broker(dir.path());
  broker.addTlsListener(certificates.brokerCertFile, certificates.brokerKeyFile);
  broker.start();
  MqttSubscriber results("test-results", broker.port(), "facet/cam1/result");
  ASSERT_TRUE(results.waitSubscribed(5s));
  auto settings = tlsSettingsFor(broker, dir.path(), certificates.caFile);
  settings.tlsInsecure = false;  // the broker's certificate names 127.0.0.1: checked
  MqttPublisher publisher(settings, "cam1");
  publisher.start();
  for (std::uint64_t id = 1; id <= 3; ++id) publisher.submit(samplePart(id));
  ASSERT_TRUE(results.waitFor([](const auto& m) { return partIds(m).size() == 3; }, 10s))
      << publisher.status().lastError;
  EXPECT_EQ(partIds(results.messages()), (std::vector<std::uint64_t>{1, 2, 3}));
  EXPECT_FALSE(publisher.status().degraded());
}

TEST(MqttPublisherTls, ABrokerCertificateNotFromTheConfiguredCaIsAClearErrorAndKeepsTheResults) {
  daemon_test::TempDir dir;
  const TestCertificates certificates(dir.path());
  MosquittoBroker broker(dir.path());
  broker.addTlsListener(certificates.brokerCertFile, certificates.brokerKeyFile);
  broker.start();
  const auto error =
      refusedOverTls(tlsSettingsFor(broker, dir.path(), certificates.foreignCaFile), dir.path());
  EXPECT_NE(error.find("certificate verify failed"), std::string::npos) << error;
  EXPECT_NE(error.find("mqtt.tls.ca_file"), std::string::npos) << error;
}

TEST(MqttPublisherTls, ABrokerCertificateForAnotherHostIsRefusedUnlessTlsInsecure) {
  daemon_test::TempDir dir;
  const TestCertificates certificates(dir.path());
  MosquittoBroker broker(dir.path());
  broker.addTlsListener(certificates.elsewhereCertFile, certificates.elsewhereKeyFile);
  broker.start();
  MqttSubscriber results("test-results", broker.port(), "facet/+/result");
  ASSERT_TRUE(results.waitSubscribed(5s));
  auto settings = tlsSettingsFor(broker, dir.path(), certificates.caFile);
  const auto error = refusedOverTls(settings, dir.path());
  EXPECT_NE(error.find("certificate verify failed"), std::string::npos) << error;
  settings.tlsInsecure = true;  // mqtt.tls.insecure: the CA is checked, the name is not
  deliveredOverTls(settings, results, 9);
}

TEST(MqttPublisherTls, ABrokerThatRequiresAClientCertificateGetsTheStationsOne) {
  daemon_test::TempDir dir;
  const TestCertificates certificates(dir.path());
  MosquittoBroker broker(dir.path());
  broker.addTlsListener(certificates.brokerCertFile, certificates.brokerKeyFile,
                        certificates.caFile);
  broker.start();
  MqttSubscriber results("test-results", broker.port(), "facet/+/result");
  ASSERT_TRUE(results.waitSubscribed(5s));
  auto settings = tlsSettingsFor(broker, dir.path(), certificates.caFile);
  // Without one: refused after the handshake, named, kept.
  const auto error = refusedOverTls(settings, dir.path());
  EXPECT_NE(error.find("certificate required"), std::string::npos) << error;
  // With the station's certificate and key: delivered.
  settings.certFile = certificates.clientCertFile;
  settings.keyFile = certificates.clientKeyFile;
  deliveredOverTls(settings, results, 5);
}

}  // namespace
}  // namespace facet::sinks_test
