#pragma once
// Encoding of result values into holding registers and back, for every ValueType and WordOrder.
// We encode float32 ourselves: libmodbus 3.1.6's modbus_set_float_* produce wrong words for some
// orders (its getters are right, and the tests cross-check against them).

#include <array>
#include <cstdint>

#include "plc/register_map.hpp"

namespace facet::plc {

struct EncodedValue {
  std::array<std::uint16_t, 2> words{};  // words[0] goes to the lower address
  int count = 0;                         // 1 or 2 registers used
  bool clamped = false;  // the value did not fit the type (or was NaN for an integer type) and
                         // was saturated (NaN -> 0); the caller reports it
};

// Encodes `value` as `output` says (type, factor, word order).
EncodedValue encodeValue(const ResultOutput& output, double value);

// Decodes the registers of `output` (words[0] at the lower address; only `count` are read).
double decodeValue(const ResultOutput& output, const std::uint16_t* words);

// The two registers of a 32-bit pattern (A = most significant byte) in the given order.
std::array<std::uint16_t, 2> orderWords(std::uint32_t bits, WordOrder order);
// Inverse of orderWords.
std::uint32_t unorderWords(const std::uint16_t* words, WordOrder order);

}  // namespace facet::plc
