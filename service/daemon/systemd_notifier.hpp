#pragma once
// Talks to systemd when facetd runs as a Type=notify service: READY once the camera and PLC are
// up, WATCHDOG pings from the inspection loop (a hung loop stops pinging and gets restarted),
// RELOADING around a recipe reload, STOPPING on shutdown. Outside systemd every call is a no-op.

#include <chrono>
#include <string>

namespace facet::service {

class SystemdNotifier {
 public:
  SystemdNotifier();
  [[nodiscard]] bool underSystemd() const { return underSystemd_; }
  // The interval at which watchdog() must be called (half of WatchdogSec), zero when disabled.
  [[nodiscard]] std::chrono::microseconds watchdogInterval() const { return watchdogInterval_; }

  void ready(const std::string& status) const;
  void reloading() const;
  void stopping() const;
  void watchdog() const;
  void status(const std::string& text) const;

 private:
  bool underSystemd_ = false;
  std::chrono::microseconds watchdogInterval_{0};
};

}  // namespace facet::service
