#include "service/daemon/systemd_notifier.hpp"

#include <systemd/sd-daemon.h>

#include <cstdlib>

namespace facet::service {

SystemdNotifier::SystemdNotifier() {
  underSystemd_ = std::getenv("NOTIFY_SOCKET") != nullptr;
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) watchdogInterval_ = std::chrono::microseconds(usec / 2);
}

void SystemdNotifier::ready(const std::string& status) const {
  if (underSystemd_) sd_notifyf(0, "READY=1\nSTATUS=%s", status.c_str());
}
void SystemdNotifier::reloading() const {
  if (underSystemd_) sd_notify(0, "RELOADING=1");
}
void SystemdNotifier::stopping() const {
  if (underSystemd_) sd_notify(0, "STOPPING=1");
}
void SystemdNotifier::watchdog() const {
  if (underSystemd_ && watchdogInterval_.count() > 0) sd_notify(0, "WATCHDOG=1");
}
void SystemdNotifier::status(const std::string& text) const {
  if (underSystemd_) sd_notifyf(0, "STATUS=%s", text.c_str());
}

}  // namespace facet::service
