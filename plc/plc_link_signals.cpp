// The PLC link's signal access: the bus's reads and writes with the signal's name, its address
// in messages, and Modbus exceptions counted and logged.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "plc/plc_link_state.hpp"
#include "plc/register_encoding.hpp"

namespace facet::plc {
namespace {

std::string addressText(const Location& at) {
  std::string text =
      (at.table == Table::Coil ? "coil " : "holding register ") + std::to_string(at.address);
  if (at.bit >= 0) text += " bit " + std::to_string(at.bit);
  return text;
}

}  // namespace

void PlcLink::State::request(const std::string& name, const std::string& what,
                             const std::function<void()>& f) {
  try {
    f();
    if (!exceptionCounts.empty()) exceptionCounts.erase(name);  // logs the next failure again
  } catch (const ModbusException& e) {
    {
      std::lock_guard lock(mutex);
      ++stats.modbusErrors;
    }
    // Log the first exception of a register and then every hundredth, so a PLC that rejects a
    // register every poll does not flood the log.
    const auto n = ++exceptionCounts[name];
    if (n == 1 || n % 100 == 0)
      spdlog::error("PLC {}: Modbus exception {} {} ({}){}", bus->describe(), what, name, e.what(),
                    n > 1 ? fmt::format(", {} times", n) : "");
    if (e.deviceBusy()) throw TryAgain{};
  }
}

bool PlcLink::State::readFlag(const char* name, const Location& at) {
  const int wire = map.wireAddress(at.address);
  bool value = false;
  request(name, "reading " + addressText(at) + " for", [&] {
    if (at.table == Table::Coil) {
      std::uint8_t bit = 0;
      bus->readCoils(wire, 1, &bit);
      value = bit != 0;
    } else {
      std::uint16_t word = 0;
      bus->readRegisters(wire, 1, &word);
      value = at.bit >= 0 ? ((word >> at.bit) & 1u) != 0 : word != 0;
    }
  });
  return value;
}

int PlcLink::State::readNumber(const char* name, const Location& at) {
  std::uint16_t word = 0;
  request(name, "reading " + addressText(at) + " for",
          [&] { bus->readRegisters(map.wireAddress(at.address), 1, &word); });
  return word;
}

void PlcLink::State::writeFlag(const char* name, const std::optional<Location>& at, bool value) {
  if (!at) return;
  const int wire = map.wireAddress(at->address);
  request(name, "writing " + addressText(*at) + " for", [&] {
    if (at->table == Table::Coil) {
      bus->writeCoil(wire, value);
    } else if (at->bit < 0) {
      const std::uint16_t word = value ? 1 : 0;
      bus->writeRegisters(wire, 1, &word);
    } else {
      // A bit inside a register the PLC may share: read, modify, write. The PLC should not
      // write the other bits of a status register while the daemon runs.
      std::uint16_t word = 0;
      bus->readRegisters(wire, 1, &word);
      const auto mask = static_cast<std::uint16_t>(1u << at->bit);
      word = value ? static_cast<std::uint16_t>(word | mask)
                   : static_cast<std::uint16_t>(word & ~mask);
      bus->writeRegisters(wire, 1, &word);
    }
  });
}

void PlcLink::State::writeNumber(const char* name, const std::optional<Location>& at, int value) {
  if (!at) return;
  const auto word = static_cast<std::uint16_t>(value);
  request(name, "writing " + addressText(*at) + " for",
          [&] { bus->writeRegisters(map.wireAddress(at->address), 1, &word); });
}

// Writes registers in as few requests as possible: consecutive addresses go in one request.
void PlcLink::State::writeRegisterRuns(std::vector<RegisterWrite> writes) {
  std::sort(writes.begin(), writes.end(),
            [](const RegisterWrite& a, const RegisterWrite& b) { return a.wire < b.wire; });
  std::size_t begin = 0;
  while (begin < writes.size()) {
    std::size_t end = begin + 1;
    while (end < writes.size() && writes[end].wire == writes[end - 1].wire + 1 &&
           static_cast<int>(end - begin) < kMaxRegistersPerWrite)
      ++end;
    std::vector<std::uint16_t> words;
    std::string names;
    for (std::size_t i = begin; i < end; ++i) {
      words.push_back(writes[i].value);
      if (names.find(writes[i].name) == std::string::npos)
        names += (names.empty() ? "" : ", ") + writes[i].name;
    }
    const int first = writes[begin].wire + map.addressBase;
    const std::string range = end - begin == 1
                                  ? "holding register " + std::to_string(first)
                                  : "holding registers " + std::to_string(first) + ".." +
                                        std::to_string(first + int(end - begin) - 1);
    request(names, "writing " + range + " for", [&] {
      bus->writeRegisters(writes[begin].wire, static_cast<int>(words.size()), words.data());
    });
    begin = end;
  }
}

}  // namespace facet::plc
