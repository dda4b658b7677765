#include "service/daemon/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace facet::service {
namespace {

void atomicAdd(std::atomic<double>& a, double by) {
  double old = a.load(std::memory_order_relaxed);
  while (!a.compare_exchange_weak(old, old + by, std::memory_order_relaxed)) {
  }
}

std::string number(double v) {
  if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
  if (std::isnan(v)) return "NaN";
  std::ostringstream s;
  s.precision(12);
  s << v;
  return s.str();
}

std::string series(const std::string& name, const std::string& labels) {
  return labels.empty() ? name : name + "{" + labels + "}";
}

std::string withLabel(const std::string& labels, const std::string& extra) {
  return labels.empty() ? extra : labels + "," + extra;
}

}  // namespace

void Counter::increment(double by) {
  atomicAdd(value_, by);
}

Histogram::Histogram(std::vector<double> upperBounds)
    : bounds_(std::move(upperBounds)),
      buckets_(std::make_unique<std::atomic<std::uint64_t>[]>(bounds_.size() + 1)) {
  if (!std::is_sorted(bounds_.begin(), bounds_.end()))
    throw std::invalid_argument("histogram bucket bounds must be sorted");
}

void Histogram::observe(double v) {
  const auto i = std::lower_bound(bounds_.begin(), bounds_.end(), v) - bounds_.begin();
  buckets_[static_cast<std::size_t>(i)].fetch_add(1, std::memory_order_relaxed);
  atomicAdd(sum_, v);
  count_.fetch_add(1, std::memory_order_relaxed);
}

std::vector<std::uint64_t> Histogram::cumulativeCounts() const {
  std::vector<std::uint64_t> out(bounds_.size() + 1);
  std::uint64_t run = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    run += buckets_[i].load(std::memory_order_relaxed);
    out[i] = run;
  }
  return out;
}

std::vector<double> latencyBucketsMs() {
  return {0.5, 1, 2, 3, 5, 7.5, 10, 15, 20, 30, 40, 50, 75, 100, 250, 500, 1000, 2500, 10000};
}

MetricsRegistry::Family& MetricsRegistry::family(const std::string& name, const std::string& help,
                                                 const char* type) {
  auto& f = families_[name];
  if (f.type.empty()) {
    f.type = type;
    f.help = help;
  } else if (f.type != type) {
    throw std::logic_error("metric " + name + " registered as " + f.type + " and " + type);
  }
  return f;
}

Counter& MetricsRegistry::counter(const std::string& name, const std::string& help,
                                  const std::string& labels) {
  std::lock_guard lock(mutex_);
  auto& slot = family(name, help, "counter").counters[labels];
  if (!slot) slot = std::make_unique<Counter>();
  return *slot;
}

Gauge& MetricsRegistry::gauge(const std::string& name, const std::string& help,
                              const std::string& labels) {
  std::lock_guard lock(mutex_);
  auto& slot = family(name, help, "gauge").gauges[labels];
  if (!slot) slot = std::make_unique<Gauge>();
  return *slot;
}

Histogram& MetricsRegistry::histogram(const std::string& name, const std::string& help,
                                      const std::vector<double>& upperBounds,
                                      const std::string& labels) {
  std::lock_guard lock(mutex_);
  auto& slot = family(name, help, "histogram").histograms[labels];
  if (!slot) slot = std::make_unique<Histogram>(upperBounds);
  return *slot;
}

std::string MetricsRegistry::exposition() const {
  std::lock_guard lock(mutex_);
  std::ostringstream out;
  for (const auto& [name, f] : families_) {
    out << "# HELP " << name << ' ' << f.help << '\n' << "# TYPE " << name << ' ' << f.type << '\n';
    for (const auto& [labels, c] : f.counters)
      out << series(name, labels) << ' ' << number(c->value()) << '\n';
    for (const auto& [labels, g] : f.gauges)
      out << series(name, labels) << ' ' << number(g->value()) << '\n';
    for (const auto& [labels, h] : f.histograms) {
      const auto counts = h->cumulativeCounts();
      for (std::size_t i = 0; i < counts.size(); ++i) {
        const std::string le =
            "le=\"" + (i < h->upperBounds().size() ? number(h->upperBounds()[i]) : "+Inf") + "\"";
        out << series(name + "_bucket", withLabel(labels, le)) << ' ' << counts[i] << '\n';
      }
      out << series(name + "_sum", labels) << ' ' << number(h->sum()) << '\n';
      out << series(name + "_count", labels) << ' ' << h->count() << '\n';
    }
  }
  return out.str();
}

Histogram& stageLatency(MetricsRegistry& metrics, const std::string& stage) {
  return metrics.histogram("facet_stage_ms", "Latency per stage", latencyBucketsMs(),
                           "stage=\"" + stage + "\"");
}

}  // namespace facet::service
