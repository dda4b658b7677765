#pragma once
// Reading parts back from the central PostgreSQL database that PostgresSink writes, for
// `facet results export --postgres`: the same PartResult the SQLite store gives, with the
// station each part came from.

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "service/engine/part_result.hpp"

namespace facet::service {

struct StationPart {
  std::string station;
  PartResult part;
};

// Parts at or after `since` (oldest first; of `station` only when given), at most `limit`
// (0 = all), measurements in the order they were written. `connection` is a libpq connection
// string; the password comes from it, PGPASSWORD or ~/.pgpass as libpq reads them. Throws
// std::runtime_error naming the server (never the password) when it cannot connect or read.
[[nodiscard]] std::vector<StationPart> readPostgresResults(
    const std::string& connection, const std::optional<std::string>& station,
    std::chrono::system_clock::time_point since, std::size_t limit = 0);

}  // namespace facet::service
