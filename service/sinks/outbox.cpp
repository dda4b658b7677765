#include "service/sinks/outbox.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <spdlog/spdlog.h>

namespace facet::service {
namespace {

constexpr const char* kExtension = ".json";

// "00000000000000000042.json" -> 42; nullopt for any other name.
std::optional<std::uint64_t> seqOf(const std::filesystem::path& file) {
  if (file.extension() != kExtension) return std::nullopt;
  const std::string stem = file.stem().string();
  if (stem.size() != 20 || stem.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  return std::stoull(stem);
}

}  // namespace

Outbox::Outbox(std::filesystem::path folder, std::uint64_t quotaBytes, std::string name)
    : folder_(std::move(folder)), quotaBytes_(quotaBytes), name_(std::move(name)) {
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  if (ec)
    throw std::runtime_error(folder_.string() + ": cannot create the outbox: " + ec.message());
  std::vector<Entry> found;
  for (const auto& entry : std::filesystem::directory_iterator(folder_, ec)) {
    if (entry.path().extension() == ".tmp") {
      // A record whose write was interrupted: never renamed, so never complete.
      std::filesystem::remove(entry.path(), ec);
      continue;
    }
    if (const auto seq = seqOf(entry.path()))
      found.push_back({*seq, static_cast<std::uint64_t>(entry.file_size(ec))});
  }
  if (ec) throw std::runtime_error(folder_.string() + ": cannot list the outbox: " + ec.message());
  std::sort(found.begin(), found.end(),
            [](const Entry& a, const Entry& b) { return a.seq < b.seq; });
  for (const auto& e : found) {
    entries_.push_back(e);
    stats_.bytes += e.bytes;
  }
  stats_.pending = entries_.size();
  stats_.recovered = entries_.size();
  if (!entries_.empty()) {
    nextSeq_ = entries_.back().seq + 1;
    spdlog::info("{}: {} results from before the restart wait in {}", name_, entries_.size(),
                 folder_.string());
  }
}

std::filesystem::path Outbox::fileOf(std::uint64_t seq) const {
  char name[32];
  std::snprintf(name, sizeof name, "%020llu", static_cast<unsigned long long>(seq));
  return folder_ / (std::string(name) + kExtension);
}

bool Outbox::append(const std::string& payload) {
  std::lock_guard lock(mutex_);
  const std::uint64_t seq = nextSeq_++;
  const auto file = fileOf(seq);
  auto tmp = file;
  tmp += ".tmp";
  bool ok = false;
  if (std::FILE* f = std::fopen(tmp.c_str(), "wb")) {
    ok = std::fwrite(payload.data(), 1, payload.size(), f) == payload.size();
    ok = std::fclose(f) == 0 && ok;
    ok = ok && std::rename(tmp.c_str(), file.c_str()) == 0;
  }
  if (!ok) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    ++stats_.writeErrors;
    // Logged every time it starts failing, then every 1000th: a full disk must not flood the log.
    if (stats_.writeErrors % 1000 == 1)
      spdlog::error("{}: cannot write {} ({} records lost so far)", name_, file.string(),
                    stats_.writeErrors);
    return false;
  }
  entries_.push_back({seq, payload.size()});
  stats_.bytes += payload.size();
  ++stats_.appended;
  while (stats_.bytes > quotaBytes_ && entries_.size() > 1) dropOldestLocked();
  stats_.pending = entries_.size();
  changed_.notify_all();
  return true;
}

void Outbox::dropOldestLocked() {
  const Entry oldest = entries_.front();
  entries_.pop_front();
  std::error_code ec;
  std::filesystem::remove(fileOf(oldest.seq), ec);
  stats_.bytes -= oldest.bytes;
  ++stats_.dropped;
  if (stats_.dropped % 1000 == 1)
    spdlog::warn("{}: quota of {} bytes full: oldest result dropped ({} dropped so far)", name_,
                 quotaBytes_, stats_.dropped);
}

std::vector<OutboxRecord> Outbox::peek(std::size_t max) {
  std::lock_guard lock(mutex_);
  std::vector<OutboxRecord> records;
  for (std::size_t i = 0; i < entries_.size() && records.size() < max;) {
    std::ifstream in(fileOf(entries_[i].seq), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) {
      spdlog::error("{}: record {} is unreadable; dropped", name_,
                    fileOf(entries_[i].seq).string());
      std::error_code ec;
      std::filesystem::remove(fileOf(entries_[i].seq), ec);
      stats_.bytes -= entries_[i].bytes;
      ++stats_.dropped;
      entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(i));
      stats_.pending = entries_.size();
      continue;
    }
    records.push_back({entries_[i].seq, text.str()});
    ++i;
  }
  return records;
}

void Outbox::remove(const std::vector<std::uint64_t>& seqs) {
  std::lock_guard lock(mutex_);
  for (const auto seq : seqs) {
    // Delivered records are the oldest ones, so this is a walk from the front.
    const auto it = std::find_if(entries_.begin(), entries_.end(),
                                 [seq](const Entry& e) { return e.seq == seq; });
    if (it == entries_.end()) continue;
    std::error_code ec;
    std::filesystem::remove(fileOf(seq), ec);
    stats_.bytes -= it->bytes;
    entries_.erase(it);
  }
  stats_.pending = entries_.size();
}

bool Outbox::waitForRecords(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [this] { return !entries_.empty() || woken_; });
  woken_ = false;
  return !entries_.empty();
}

void Outbox::wake() {
  std::lock_guard lock(mutex_);
  woken_ = true;
  changed_.notify_all();
}

OutboxStats Outbox::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace facet::service
