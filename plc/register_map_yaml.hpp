#pragma once
// Reads a RegisterMap from YAML (yaml-cpp), reporting bad input as "file:line:column: message".
//
//   address_base: 0            # 0 or 1 (default 0)
//   control:
//     trigger:       {coil: 0}            # a coil
//     result_ack:    {register: 10, bit: 1}  # a bit of a holding register
//     recipe_select: {register: 11}       # numbers are whole holding registers
//     enable:        {coil: 3}
//   status:
//     ready: {coil: 16}   busy: ...  result_valid: ...  pass: ...  completed_toggle: ...
//     missed_trigger: ...  error: ...  error_code: {register: 20}  heartbeat: {register: 21}
//     inspection_counter: {register: 22}  active_recipe: {register: 23}
//   results:
//     - {name: hole.diameter_mm, register: 100, type: float32, word_order: CDAB}
//     - {name: offset_x_mm, register: 102, type: scaled_int16, factor: 100}
//
// Unknown keys are errors. The parsed map is validate()d; its issues are errors too (each entry
// carries its origin, so they read "station.yaml:14:7: ...").

#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>

#include "plc/register_map.hpp"

namespace facet::plc {

// Bad register map input; what() is "file:line:column: message" (several lines when validation
// found several issues).
struct RegisterMapError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Parses the map under `node`; `fileName` is used in messages. Throws RegisterMapError.
RegisterMap parseRegisterMap(const YAML::Node& node, const std::string& fileName);

// Parses YAML text (a whole document holding the map). Throws RegisterMapError, also for YAML
// syntax errors.
RegisterMap parseRegisterMapText(const std::string& text, const std::string& fileName);

// Loads a file holding the map. Throws RegisterMapError (also when unreadable).
RegisterMap loadRegisterMap(const std::string& path);

}  // namespace facet::plc
