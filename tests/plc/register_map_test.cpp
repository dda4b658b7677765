// RegisterMap validation, value encoding for every type and word order, and the YAML parser.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <typeinfo>

#include <modbus.h>

#include "plc/register_encoding.hpp"
#include "plc/register_map.hpp"
#include "plc/register_map_yaml.hpp"

namespace facet::plc {
namespace {

using ::testing::HasSubstr;

constexpr WordOrder kOrders[] = {WordOrder::ABCD, WordOrder::CDAB, WordOrder::BADC,
                                 WordOrder::DCBA};

Location coil(int address) {
  return {Table::Coil, address, -1, ""};
}
Location reg(int address, int bit = -1) {
  return {Table::HoldingRegister, address, bit, ""};
}

std::string allMessages(const std::vector<MapIssue>& issues) {
  std::string text;
  for (const auto& issue : issues) text += issue.message + "\n";
  return text;
}

// --- encoding -------------------------------------------------------------------------------

TEST(RegisterEncoding, Float32WordOrdersPlaceTheBytesOfOnePointZero) {
  // 1.0f is 0x3F800000: A=3F B=80 C=00 D=00.
  ResultOutput out{"x", 0, ValueType::Float32, 1.0, WordOrder::ABCD, ""};
  const std::array<std::array<std::uint16_t, 2>, 4> expected = {
      {{0x3F80, 0x0000}, {0x0000, 0x3F80}, {0x803F, 0x0000}, {0x0000, 0x803F}}};
  for (int i = 0; i < 4; ++i) {
    out.wordOrder = kOrders[i];
    const auto encoded = encodeValue(out, 1.0);
    EXPECT_EQ(encoded.count, 2);
    EXPECT_EQ(encoded.words, expected[i]) << toString(kOrders[i]);
  }
}

TEST(RegisterEncoding, Float32AgreesWithLibmodbusGetters) {
  // libmodbus 3.1.6's getters are right (its setters are not): they decode our words.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> value(-1e6f, 1e6f);
  using Getter = float (*)(const std::uint16_t*);
  const Getter getters[] = {modbus_get_float_abcd, modbus_get_float_cdab, modbus_get_float_badc,
                            modbus_get_float_dcba};
  for (int trial = 0; trial < 200; ++trial) {
    const float v = trial == 0 ? -0.0f : value(rng);
    for (int i = 0; i < 4; ++i) {
      const ResultOutput out{"x", 0, ValueType::Float32, 1.0, kOrders[i], ""};
      const auto encoded = encodeValue(out, v);
      EXPECT_EQ(std::bit_cast<std::uint32_t>(getters[i](encoded.words.data())),
                std::bit_cast<std::uint32_t>(v))
          << toString(kOrders[i]) << " " << v;
      EXPECT_EQ(static_cast<float>(decodeValue(out, encoded.words.data())), v);
    }
  }
}

TEST(RegisterEncoding, Int32WordOrders) {
  // -2 = 0xFFFFFFFE; 0x01020304 shows every byte's place.
  for (const auto order : kOrders) {
    const ResultOutput out{"x", 0, ValueType::Int32, 1.0, order, ""};
    for (const double v : {-2.0, 16909060.0, 2147483647.0, -2147483648.0, 0.0}) {
      const auto encoded = encodeValue(out, v);
      EXPECT_FALSE(encoded.clamped);
      EXPECT_EQ(decodeValue(out, encoded.words.data()), v) << toString(order);
    }
  }
  const ResultOutput badc{"x", 0, ValueType::Int32, 1.0, WordOrder::BADC, ""};
  EXPECT_EQ(encodeValue(badc, 16909060.0).words, (std::array<std::uint16_t, 2>{0x0201, 0x0403}));
  const ResultOutput dcba{"x", 0, ValueType::Int32, 1.0, WordOrder::DCBA, ""};
  EXPECT_EQ(encodeValue(dcba, 16909060.0).words, (std::array<std::uint16_t, 2>{0x0403, 0x0201}));
}

TEST(RegisterEncoding, ScaledAndInt16RoundAndSaturate) {
  const ResultOutput s16{"x", 0, ValueType::ScaledInt16, 100.0, WordOrder::ABCD, ""};
  auto e = encodeValue(s16, -12.345);
  EXPECT_EQ(e.count, 1);
  EXPECT_EQ(e.words[0], static_cast<std::uint16_t>(static_cast<std::int16_t>(-1235)));
  EXPECT_DOUBLE_EQ(decodeValue(s16, e.words.data()), -12.35);
  e = encodeValue(s16, 400.0);  // 40000 does not fit int16
  EXPECT_TRUE(e.clamped);
  EXPECT_EQ(e.words[0], 32767);

  const ResultOutput s32{"x", 0, ValueType::ScaledInt32, 1000.0, WordOrder::CDAB, ""};
  e = encodeValue(s32, 123456.789);
  EXPECT_FALSE(e.clamped);
  EXPECT_DOUBLE_EQ(decodeValue(s32, e.words.data()), 123456.789);

  const ResultOutput i16{"x", 0, ValueType::Int16, 1.0, WordOrder::ABCD, ""};
  e = encodeValue(i16, std::numeric_limits<double>::quiet_NaN());
  EXPECT_TRUE(e.clamped);
  EXPECT_EQ(e.words[0], 0);
  e = encodeValue(i16, -40000.0);
  EXPECT_TRUE(e.clamped);
  EXPECT_EQ(e.words[0], 0x8000);
}

// --- validation -----------------------------------------------------------------------------

RegisterMap goodMap() {
  RegisterMap map;
  map.control.trigger = coil(0);
  map.control.resultAck = coil(1);
  map.status.resultValid = coil(2);
  map.status.busy = reg(10, 0);
  map.status.pass = reg(10, 1);  // another bit of the same register: fine
  map.status.inspectionCounter = reg(11);
  map.results.push_back({"d", 100, ValueType::Float32, 1.0, WordOrder::CDAB, ""});
  map.results.push_back({"x", 102, ValueType::Int16, 1.0, WordOrder::ABCD, ""});
  return map;
}

TEST(RegisterMapValidate, AGoodMapHasNoIssues) {
  EXPECT_THAT(goodMap().validate(), ::testing::IsEmpty());
}

TEST(RegisterMapValidate, OverlapsNameBothEntries) {
  RegisterMap map = goodMap();
  map.status.ready = coil(1);  // the ack's coil
  map.results.push_back({"y", 101, ValueType::Int16, 1.0, WordOrder::ABCD, "m.yaml:9:5"});
  map.status.error = reg(10, 1);  // pass's bit
  const std::string text = allMessages(map.validate());
  EXPECT_THAT(text, HasSubstr("control.result_ack and status.ready overlap at coil 1"));
  EXPECT_THAT(text,
              HasSubstr("result.d and result.y (m.yaml:9:5) overlap at holding register 101"));
  EXPECT_THAT(text, HasSubstr("status.pass and status.error overlap at holding register 10"));
  EXPECT_EQ(map.validate().size(), 3u);
}

TEST(RegisterMapValidate, WholeRegisterOverlapsItsBits) {
  RegisterMap map = goodMap();
  map.status.errorCode = reg(10);
  const std::string text = allMessages(map.validate());
  EXPECT_THAT(text, HasSubstr("status.busy and status.error_code overlap"));
  EXPECT_THAT(text, HasSubstr("status.pass and status.error_code overlap"));
}

TEST(RegisterMapValidate, OutOfRangeEntries) {
  RegisterMap map = goodMap();
  map.results.push_back({"tail", 65535, ValueType::Float32, 1.0, WordOrder::ABCD, ""});
  map.status.error = reg(12, 16);
  map.status.ready = {Table::Coil, 3, 2, ""};
  map.status.heartbeat = coil(4);
  map.results.push_back({"s", 200, ValueType::ScaledInt16, 0.0, WordOrder::ABCD, ""});
  map.results.push_back({"d", 300, ValueType::Int16, 1.0, WordOrder::ABCD, ""});
  const std::string text = allMessages(map.validate());
  EXPECT_THAT(text, HasSubstr("result.tail: float32 at address 65535 does not fit in 0..65535"));
  EXPECT_THAT(text, HasSubstr("status.error: bit 16 is outside 0..15"));
  EXPECT_THAT(text, HasSubstr("status.ready: a coil has no bits"));
  EXPECT_THAT(text, HasSubstr("status.heartbeat: a number needs a whole holding register"));
  EXPECT_THAT(text, HasSubstr("result.s: scale factor"));
  EXPECT_THAT(text, HasSubstr("result.d: duplicate name"));
}

TEST(RegisterMapValidate, OneBasedAddressesStartAtOne) {
  RegisterMap map = goodMap();
  map.addressBase = 1;
  map.control.trigger = coil(0);  // wire -1
  const std::string text = allMessages(map.validate());
  EXPECT_THAT(text, HasSubstr("control.trigger: address 0 is outside 1..65536"));
  map.control.trigger = coil(65536);  // the last coil, one-based
  EXPECT_THAT(map.validate(), ::testing::IsEmpty());
}

// --- YAML -----------------------------------------------------------------------------------

const char* kYaml = R"(address_base: 1
control:
  trigger: {coil: 1}
  result_ack: {coil: 2}
  recipe_select: {register: 5}
status:
  busy: {register: 10, bit: 0}
  result_valid: {register: 10, bit: 1}
  inspection_counter: {register: 11}
results:
  - {name: diameter, register: 101, type: float32, word_order: cdab}
  - {name: offset, register: 103, type: scaled_int16, factor: 100}
)";

TEST(RegisterMapYaml, ParsesAGoodMap) {
  const RegisterMap map = parseRegisterMapText(kYaml, "map.yaml");
  EXPECT_EQ(map.addressBase, 1);
  ASSERT_TRUE(map.control.trigger);
  EXPECT_EQ(map.control.trigger->table, Table::Coil);
  EXPECT_EQ(map.wireAddress(map.control.trigger->address), 0);
  ASSERT_TRUE(map.status.resultValid);
  EXPECT_EQ(map.status.resultValid->bit, 1);
  EXPECT_EQ(map.status.resultValid->origin, "map.yaml:8:17");
  ASSERT_EQ(map.results.size(), 2u);
  EXPECT_EQ(map.results[0].wordOrder, WordOrder::CDAB);
  EXPECT_EQ(map.results[1].type, ValueType::ScaledInt16);
  EXPECT_EQ(map.results[1].factor, 100.0);
}

void expectError(const std::string& yaml, const std::string& expected) {
  try {
    parseRegisterMapText(yaml, "map.yaml");
    ADD_FAILURE() << "no error for:\n" << yaml;
  } catch (const RegisterMapError& e) {
    EXPECT_THAT(e.what(), HasSubstr(expected)) << yaml;
  }
}

TEST(RegisterMapYaml, ErrorsNameFileLineAndColumn) {
  expectError("control:\n  trigger: {coil: 1}\n  triger: {coil: 2}\n",
              "map.yaml:3:3: unknown key 'triger' in control");
  expectError("results:\n  - {name: a, register: 1, type: float64}\n",
              "map.yaml:2:34: result 'a': unknown type 'float64'");
  expectError("results:\n  - {name: a, register: x1}\n",
              "map.yaml:2:25: result 'a'.register must be an integer, not 'x1'");
  expectError("results:\n  - {name: a, register: 1, type: scaled_int16}\n",
              "map.yaml:2:5: result 'a': a scaled type needs a 'factor'");
  expectError("status:\n  busy: {coil: 1, register: 2}\n",
              "map.yaml:2:9: status.busy needs exactly one of 'coil' or 'register'");
  expectError("control: [1, 2\n", "map.yaml:2:1:");
  expectError("address_base: 2\n", "map.yaml:1:15: address_base must be 0 or 1");
}

TEST(RegisterMapYaml, OverlapErrorsNameBothEntriesWithPositions) {
  const std::string yaml =
      "results:\n"
      "  - {name: a, register: 100, type: float32}\n"
      "  - {name: b, register: 101, type: int16}\n";
  expectError(yaml,
              "result.a (map.yaml:2:5) and result.b (map.yaml:3:5) overlap at holding "
              "register 101");
}

TEST(RegisterMapYaml, UnreadableFileIsNamed) {
  try {
    loadRegisterMap("/nonexistent/plc.yaml");
    FAIL();
  } catch (const RegisterMapError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/plc.yaml: cannot read"));
  }
}

}  // namespace
}  // namespace facet::plc

namespace facet::plc {
namespace {

// Byte-level mutations of a good map: every outcome is a map or a RegisterMapError, never another
// exception or a crash (the hardening fuzzer goes further; this keeps the contract in CI).
TEST(RegisterMapYaml, MutatedInputGivesAMapOrAClearError) {
  const std::string good = kYaml;
  std::mt19937 rng(1234);
  const std::string alphabet = "{}[]:,-#&*!|>'\"%@` \n\t0123456789abcxyz.";
  int errors = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string text = good;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % text.size();
      switch (rng() % 3) {
        case 0:
          text[at] = alphabet[rng() % alphabet.size()];
          break;
        case 1:
          text.erase(at, 1 + rng() % 8);
          break;
        default:
          text.insert(text.begin() + static_cast<std::ptrdiff_t>(at),
                      alphabet[rng() % alphabet.size()]);
          break;
      }
      if (text.empty()) text.push_back('x');
    }
    try {
      parseRegisterMapText(text, "fuzz.yaml");
    } catch (const RegisterMapError& e) {
      ++errors;
      EXPECT_THAT(e.what(), HasSubstr("fuzz.yaml")) << "the error does not name the file";
    } catch (const std::exception& e) {
      ADD_FAILURE() << "unexpected " << typeid(e).name() << ": " << e.what() << "\n" << text;
    }
  }
  EXPECT_GT(errors, 100);  // the mutations do break the map
}

}  // namespace
}  // namespace facet::plc
