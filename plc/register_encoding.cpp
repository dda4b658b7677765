#include "plc/register_encoding.hpp"

#include <bit>
#include <cmath>
#include <limits>

namespace facet::plc {
namespace {

// Rounds to the nearest integer of [lo, hi]; NaN and overflow saturate and mark the result.
std::int64_t roundInto(double value, std::int64_t lo, std::int64_t hi, bool& clamped) {
  if (std::isnan(value)) {
    clamped = true;
    return 0;
  }
  const double r = std::round(value);
  if (r < static_cast<double>(lo)) {
    clamped = true;
    return lo;
  }
  if (r > static_cast<double>(hi)) {
    clamped = true;
    return hi;
  }
  return static_cast<std::int64_t>(r);
}

std::uint16_t swapBytes(std::uint16_t w) {
  return static_cast<std::uint16_t>((w >> 8) | (w << 8));
}

bool isScaled(ValueType type) {
  return type == ValueType::ScaledInt16 || type == ValueType::ScaledInt32;
}

}  // namespace

std::array<std::uint16_t, 2> orderWords(std::uint32_t bits, WordOrder order) {
  const auto high = static_cast<std::uint16_t>(bits >> 16);    // A B
  const auto low = static_cast<std::uint16_t>(bits & 0xFFFF);  // C D
  switch (order) {
    case WordOrder::ABCD:
      return {high, low};
    case WordOrder::CDAB:
      return {low, high};
    case WordOrder::BADC:
      return {swapBytes(high), swapBytes(low)};
    case WordOrder::DCBA:
      return {swapBytes(low), swapBytes(high)};
  }
  return {high, low};
}

std::uint32_t unorderWords(const std::uint16_t* words, WordOrder order) {
  std::uint16_t high = words[0];
  std::uint16_t low = words[1];
  switch (order) {
    case WordOrder::ABCD:
      break;
    case WordOrder::CDAB:
      std::swap(high, low);
      break;
    case WordOrder::BADC:
      high = swapBytes(words[0]);
      low = swapBytes(words[1]);
      break;
    case WordOrder::DCBA:
      high = swapBytes(words[1]);
      low = swapBytes(words[0]);
      break;
  }
  return (static_cast<std::uint32_t>(high) << 16) | low;
}

EncodedValue encodeValue(const ResultOutput& output, double value) {
  EncodedValue encoded;
  encoded.count = registerCount(output.type);
  if (isScaled(output.type)) value *= output.factor;
  switch (output.type) {
    case ValueType::Int16:
    case ValueType::ScaledInt16: {
      const auto v = roundInto(value, std::numeric_limits<std::int16_t>::min(),
                               std::numeric_limits<std::int16_t>::max(), encoded.clamped);
      encoded.words[0] = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
      break;
    }
    case ValueType::Int32:
    case ValueType::ScaledInt32: {
      const auto v = roundInto(value, std::numeric_limits<std::int32_t>::min(),
                               std::numeric_limits<std::int32_t>::max(), encoded.clamped);
      encoded.words =
          orderWords(static_cast<std::uint32_t>(static_cast<std::int32_t>(v)), output.wordOrder);
      break;
    }
    case ValueType::Float32: {
      const double limit = std::numeric_limits<float>::max();
      if (std::isfinite(value) && std::fabs(value) > limit) encoded.clamped = true;
      const float f = std::isfinite(value) && std::fabs(value) > limit
                          ? static_cast<float>(std::copysign(limit, value))
                          : static_cast<float>(value);
      encoded.words = orderWords(std::bit_cast<std::uint32_t>(f), output.wordOrder);
      break;
    }
  }
  return encoded;
}

double decodeValue(const ResultOutput& output, const std::uint16_t* words) {
  double value = 0.0;
  switch (output.type) {
    case ValueType::Int16:
    case ValueType::ScaledInt16:
      value = static_cast<std::int16_t>(words[0]);
      break;
    case ValueType::Int32:
    case ValueType::ScaledInt32:
      value = static_cast<std::int32_t>(unorderWords(words, output.wordOrder));
      break;
    case ValueType::Float32:
      value = std::bit_cast<float>(unorderWords(words, output.wordOrder));
      break;
  }
  return isScaled(output.type) ? value / output.factor : value;
}

}  // namespace facet::plc
