#pragma once
// Parts as the image archive's tests hand them over: an id, a verdict and the time of now.

#include <chrono>
#include <cstdint>

#include "service/engine/part_result.hpp"

namespace facet::service::test {

inline PartResult partWith(std::uint64_t id, Verdict verdict) {
  PartResult p;
  p.partId = id;
  p.verdict = verdict;
  p.time = std::chrono::system_clock::now();
  return p;
}

}  // namespace facet::service::test
