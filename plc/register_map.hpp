#pragma once
// RegisterMap: where every handshake signal and every recipe output lives in the PLC's Modbus
// address space. It comes from the station config (see register_map_yaml.hpp) and is checked with
// validate() before a link is opened, so that two signals never share a register by accident.
//
// Addresses are written as the map's author counts them: `addressBase` 0 means the first
// holding register is 0 (what goes on the wire), 1 means it is 1 (the "40001 - 40000" habit of
// many PLC manuals). wireAddress() turns a written address into the wire address.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace facet::plc {

// The Modbus table a signal lives in.
enum class Table {
  HoldingRegister,  // 16-bit read/write registers (function codes 3, 6, 16)
  Coil,             // single read/write bits (function codes 1, 5, 15)
};

// Where one signal lives: a coil, a whole holding register, or one bit of a holding register.
struct Location {
  Table table = Table::HoldingRegister;
  int address = -1;    // as written in the map, counted from RegisterMap::addressBase
  int bit = -1;        // 0..15 for a bit inside a holding register; -1: the whole register / coil
  std::string origin;  // where the entry was defined, e.g. "station.yaml:14:7"; may be empty
};

// Signals the PLC writes and the daemon reads. A flag is a coil, a register bit or a whole
// register (non-zero = set); a number is a whole holding register (unsigned 16 bit).
struct ControlSignals {
  std::optional<Location> trigger;       // flag; rising edge starts an inspection
  std::optional<Location> resultAck;     // flag; rising edge acknowledges a valid result
  std::optional<Location> recipeSelect;  // number; recipe the PLC asks for
  std::optional<Location> enable;        // flag; when configured and 0, triggers are ignored
};

// Signals the daemon writes and the PLC reads.
struct StatusSignals {
  std::optional<Location> ready;              // flag; link up and daemon accepting triggers
  std::optional<Location> busy;               // flag; trigger accepted, result not yet written
  std::optional<Location> resultValid;        // flag; all result registers hold one result
  std::optional<Location> pass;               // flag; verdict of the valid result (1 = pass)
  std::optional<Location> completedToggle;    // flag; flips with every result written
  std::optional<Location> missedTrigger;      // flag; a trigger came while busy (latched until
                                              // the next accepted trigger)
  std::optional<Location> error;              // flag; the result carries a non-zero error code
  std::optional<Location> errorCode;          // number; 0 = no error
  std::optional<Location> heartbeat;          // number; incremented every heartbeat period
  std::optional<Location> inspectionCounter;  // number; counter of the result (wraps at 65536)
  std::optional<Location> activeRecipe;       // number; recipe the daemon runs
};

// How a result value is stored in holding registers.
enum class ValueType {
  Int16,        // one register, two's complement, value rounded to nearest
  Int32,        // two registers, two's complement, value rounded to nearest
  ScaledInt16,  // one register holding round(value * factor)
  ScaledInt32,  // two registers holding round(value * factor)
  Float32,      // two registers, IEEE 754 single precision
};

// Order of the four bytes A B C D (A most significant) of a 32-bit value in two registers.
// The first letter pair goes to the lower address. 16-bit values ignore it.
enum class WordOrder {
  ABCD,  // big-endian words, big-endian bytes (Modbus default)
  CDAB,  // word swap (many PLCs, e.g. "little-endian word order")
  BADC,  // byte swap inside each word
  DCBA,  // fully reversed
};

// One recipe output (a diameter, an offset, an angle, a score) mapped to holding registers.
struct ResultOutput {
  std::string name;  // the recipe output's name, e.g. "hole.diameter_mm"
  int address = -1;  // first holding register, counted from RegisterMap::addressBase
  ValueType type = ValueType::Float32;
  double factor = 1.0;  // scaled types only: the register holds round(value * factor)
  WordOrder wordOrder = WordOrder::ABCD;
  std::string origin;  // where the entry was defined, e.g. "station.yaml:20:5"; may be empty
};

// Number of holding registers a value of this type occupies (1 or 2).
int registerCount(ValueType type);

// Names used in config files and messages: "int16", "int32", "scaled_int16", "scaled_int32",
// "float32"; "ABCD", "CDAB", "BADC", "DCBA"; "holding_register", "coil".
std::string toString(ValueType type);
std::string toString(WordOrder order);
std::string toString(Table table);
std::optional<ValueType> parseValueType(const std::string& name);  // also accepts "scaled_int"
                                                                   // (= scaled_int32)
std::optional<WordOrder> parseWordOrder(const std::string& name);  // case-insensitive

// One problem found by RegisterMap::validate().
struct MapIssue {
  std::string message;  // names every entry involved, with its origin when known
  std::string origin;   // origin of the entry the issue is reported at (for two entries: the
                        // later one); empty when unknown
};

// "origin: message", or the message alone when the origin is unknown.
std::string describe(const MapIssue& issue);

struct RegisterMap {
  int addressBase = 0;  // 0: addresses are wire addresses; 1: address 1 is wire address 0
  ControlSignals control;
  StatusSignals status;
  std::vector<ResultOutput> results;

  // The address sent on the wire for an address written in this map.
  int wireAddress(int writtenAddress) const { return writtenAddress - addressBase; }

  // The output mapped under `name`, or nullptr.
  const ResultOutput* findResult(const std::string& name) const;

  // Every problem of the map: addresses below the base or beyond the 16-bit address space, bits
  // outside 0..15, bits on coils, numbers or results on coils, non-finite or zero scale factors,
  // duplicate result names, an addressBase other than 0 or 1, and any two entries that share a
  // coil, a register or a register bit (the message names BOTH entries). Empty when the map is
  // usable.
  std::vector<MapIssue> validate() const;
};

// A named signal of the map, for generic code (validation, the simulator, messages):
// "control.trigger", "status.busy", "result.<name>".
struct NamedLocation {
  std::string name;
  const Location* location;
  bool isNumber;  // a whole register read as a number (not a flag)
};
std::vector<NamedLocation> namedSignals(const RegisterMap& map);

}  // namespace facet::plc
