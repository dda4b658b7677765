#pragma once
// Prometheus metrics: counters, gauges and histograms, rendered in the text exposition format
// (version 0.0.4) for /metrics. Updating a metric is lock-free; registering one takes a lock.

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace facet::service {

class Counter {
 public:
  void increment(double by = 1.0);
  [[nodiscard]] double value() const { return value_.load(std::memory_order_relaxed); }

 private:
  std::atomic<double> value_{0.0};
};

class Gauge {
 public:
  void set(double v) { value_.store(v, std::memory_order_relaxed); }
  [[nodiscard]] double value() const { return value_.load(std::memory_order_relaxed); }

 private:
  std::atomic<double> value_{0.0};
};

class Histogram {
 public:
  explicit Histogram(std::vector<double> upperBounds);
  void observe(double v);
  [[nodiscard]] const std::vector<double>& upperBounds() const { return bounds_; }
  // Cumulative counts per bucket (the last is +Inf), the sum and the count.
  [[nodiscard]] std::vector<std::uint64_t> cumulativeCounts() const;
  [[nodiscard]] double sum() const { return sum_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t count() const { return count_.load(std::memory_order_relaxed); }

 private:
  std::vector<double> bounds_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> buckets_;  // per bucket, not cumulative
  std::atomic<double> sum_{0.0};
  std::atomic<std::uint64_t> count_{0};
};

// Latency buckets in milliseconds, from 0.5 ms to 10 s.
std::vector<double> latencyBucketsMs();

class MetricsRegistry {
 public:
  // `labels` is the label set in exposition syntax without braces, e.g. `stage="inspect"`.
  // The same name and labels return the same metric. References stay valid for the registry's
  // lifetime.
  Counter& counter(const std::string& name, const std::string& help,
                   const std::string& labels = "");
  Gauge& gauge(const std::string& name, const std::string& help, const std::string& labels = "");
  Histogram& histogram(const std::string& name, const std::string& help,
                       const std::vector<double>& upperBounds, const std::string& labels = "");

  [[nodiscard]] std::string exposition() const;

 private:
  struct Family {
    std::string help;
    std::string type;
    std::map<std::string, std::unique_ptr<Counter>> counters;
    std::map<std::string, std::unique_ptr<Gauge>> gauges;
    std::map<std::string, std::unique_ptr<Histogram>> histograms;
  };
  Family& family(const std::string& name, const std::string& help, const char* type);
  mutable std::mutex mutex_;
  std::map<std::string, Family> families_;
};

// The latency histogram of one stage of facetd's pipeline (trigger, grab, inspect, plc_write,
// publish, total), in milliseconds.
Histogram& stageLatency(MetricsRegistry& metrics, const std::string& stage);

}  // namespace facet::service
