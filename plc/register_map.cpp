#include "plc/register_map.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <tuple>

namespace facet::plc {
namespace {

// One coil or one register bit range claimed by an entry; used to find overlaps.
struct Claim {
  std::string name;
  std::string origin;
  Table table;
  int wire;            // wire address of the coil / register
  std::uint16_t mask;  // bits of the register claimed (coils: 1)
};

std::string describeEntry(const std::string& name, const std::string& origin) {
  return origin.empty() ? name : name + " (" + origin + ")";
}

std::string upper(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return text;
}

std::string addressText(const RegisterMap& map, const Location& location) {
  std::string text = toString(location.table) + " " + std::to_string(location.address);
  if (location.bit >= 0) text += " bit " + std::to_string(location.bit);
  if (map.addressBase != 0) text += " (base " + std::to_string(map.addressBase) + ")";
  return text;
}

// Checks one signal's own fields and appends its claims.
void checkSignal(const RegisterMap& map, const NamedLocation& signal, std::vector<Claim>& claims,
                 std::vector<MapIssue>& issues) {
  const Location& at = *signal.location;
  const std::string& who = signal.name;
  const int wire = map.wireAddress(at.address);
  bool ok = true;
  if (wire < 0 || wire > 0xFFFF) {
    issues.push_back({who + ": address " + std::to_string(at.address) + " is outside " +
                          std::to_string(map.addressBase) + ".." +
                          std::to_string(0xFFFF + map.addressBase),
                      at.origin});
    ok = false;
  }
  if (at.table == Table::Coil && at.bit >= 0) {
    issues.push_back(
        {who + ": a coil has no bits (bit " + std::to_string(at.bit) + ")", at.origin});
    ok = false;
  }
  if (at.bit < -1 || at.bit > 15) {
    issues.push_back({who + ": bit " + std::to_string(at.bit) + " is outside 0..15", at.origin});
    ok = false;
  }
  if (signal.isNumber && (at.table != Table::HoldingRegister || at.bit >= 0)) {
    issues.push_back(
        {who + ": a number needs a whole holding register, not " + addressText(map, at),
         at.origin});
    ok = false;
  }
  if (!ok) return;
  const std::uint16_t mask =
      at.table == Table::Coil ? 1
                              : (at.bit >= 0 ? static_cast<std::uint16_t>(1u << at.bit) : 0xFFFF);
  claims.push_back({signal.name, at.origin, at.table, wire, mask});
}

void checkResult(const RegisterMap& map, const ResultOutput& output, std::vector<Claim>& claims,
                 std::vector<MapIssue>& issues) {
  const std::string name = "result." + output.name;
  const std::string& who = name;
  if (output.name.empty()) issues.push_back({who + ": the result has no name", output.origin});
  const bool scaled =
      output.type == ValueType::ScaledInt16 || output.type == ValueType::ScaledInt32;
  if (scaled && (!std::isfinite(output.factor) || output.factor == 0.0))
    issues.push_back(
        {who + ": scale factor " + std::to_string(output.factor) + " must be finite and non-zero",
         output.origin});
  const int count = registerCount(output.type);
  const int wire = map.wireAddress(output.address);
  if (wire < 0 || wire + count - 1 > 0xFFFF) {
    issues.push_back({who + ": " + toString(output.type) + " at address " +
                          std::to_string(output.address) + " does not fit in " +
                          std::to_string(map.addressBase) + ".." +
                          std::to_string(0xFFFF + map.addressBase),
                      output.origin});
    return;
  }
  for (int i = 0; i < count; ++i)
    claims.push_back({name, output.origin, Table::HoldingRegister, wire + i, 0xFFFF});
}

}  // namespace

int registerCount(ValueType type) {
  return type == ValueType::Int16 || type == ValueType::ScaledInt16 ? 1 : 2;
}

std::string toString(ValueType type) {
  switch (type) {
    case ValueType::Int16:
      return "int16";
    case ValueType::Int32:
      return "int32";
    case ValueType::ScaledInt16:
      return "scaled_int16";
    case ValueType::ScaledInt32:
      return "scaled_int32";
    case ValueType::Float32:
      return "float32";
  }
  return "?";
}

std::string toString(WordOrder order) {
  switch (order) {
    case WordOrder::ABCD:
      return "ABCD";
    case WordOrder::CDAB:
      return "CDAB";
    case WordOrder::BADC:
      return "BADC";
    case WordOrder::DCBA:
      return "DCBA";
  }
  return "?";
}

std::string toString(Table table) {
  return table == Table::Coil ? "coil" : "holding_register";
}

std::optional<ValueType> parseValueType(const std::string& name) {
  if (name == "int16") return ValueType::Int16;
  if (name == "int32") return ValueType::Int32;
  if (name == "scaled_int16") return ValueType::ScaledInt16;
  if (name == "scaled_int32" || name == "scaled_int") return ValueType::ScaledInt32;
  if (name == "float32") return ValueType::Float32;
  return std::nullopt;
}

std::optional<WordOrder> parseWordOrder(const std::string& name) {
  const std::string u = upper(name);
  if (u == "ABCD") return WordOrder::ABCD;
  if (u == "CDAB") return WordOrder::CDAB;
  if (u == "BADC") return WordOrder::BADC;
  if (u == "DCBA") return WordOrder::DCBA;
  return std::nullopt;
}

const ResultOutput* RegisterMap::findResult(const std::string& name) const {
  for (const auto& output : results)
    if (output.name == name) return &output;
  return nullptr;
}

std::vector<NamedLocation> namedSignals(const RegisterMap& map) {
  std::vector<NamedLocation> signals;
  auto add = [&](const char* name, const std::optional<Location>& at, bool isNumber) {
    if (at) signals.push_back({name, &*at, isNumber});
  };
  const auto& c = map.control;
  add("control.trigger", c.trigger, false);
  add("control.result_ack", c.resultAck, false);
  add("control.recipe_select", c.recipeSelect, true);
  add("control.enable", c.enable, false);
  const auto& s = map.status;
  add("status.ready", s.ready, false);
  add("status.busy", s.busy, false);
  add("status.result_valid", s.resultValid, false);
  add("status.pass", s.pass, false);
  add("status.completed_toggle", s.completedToggle, false);
  add("status.missed_trigger", s.missedTrigger, false);
  add("status.error", s.error, false);
  add("status.error_code", s.errorCode, true);
  add("status.heartbeat", s.heartbeat, true);
  add("status.inspection_counter", s.inspectionCounter, true);
  add("status.active_recipe", s.activeRecipe, true);
  return signals;
}

std::string describe(const MapIssue& issue) {
  return issue.origin.empty() ? issue.message : issue.origin + ": " + issue.message;
}

std::vector<MapIssue> RegisterMap::validate() const {
  std::vector<MapIssue> issues;
  if (addressBase != 0 && addressBase != 1)
    issues.push_back({"address_base " + std::to_string(addressBase) + " must be 0 or 1", ""});

  std::vector<Claim> claims;
  for (const auto& signal : namedSignals(*this)) checkSignal(*this, signal, claims, issues);
  std::set<std::string> names;
  for (const auto& output : results) {
    if (!output.name.empty() && !names.insert(output.name).second) {
      const ResultOutput* first = findResult(output.name);
      issues.push_back({"result." + output.name + ": duplicate name, first defined as " +
                            describeEntry("result." + first->name, first->origin),
                        output.origin});
    }
    checkResult(*this, output, claims, issues);
  }

  // Overlaps: sort by (table, address) so only neighbours with the same register can collide;
  // a result claims each of its registers, so one overlap may show up once per shared register
  // and is reported once per pair of entries.
  std::stable_sort(claims.begin(), claims.end(), [](const Claim& a, const Claim& b) {
    return std::tie(a.table, a.wire) < std::tie(b.table, b.wire);
  });
  std::set<std::pair<std::string, std::string>> reported;
  for (std::size_t i = 0; i < claims.size(); ++i) {
    for (std::size_t j = i + 1; j < claims.size(); ++j) {
      const Claim& a = claims[i];
      const Claim& b = claims[j];
      if (b.table != a.table || b.wire != a.wire) break;
      if ((a.mask & b.mask) == 0 || a.name == b.name) continue;
      if (!reported.insert({a.name, b.name}).second) continue;
      const std::string what = a.table == Table::Coil
                                   ? "coil " + std::to_string(a.wire + addressBase)
                                   : "holding register " + std::to_string(a.wire + addressBase);
      issues.push_back({describeEntry(a.name, a.origin) + " and " +
                            describeEntry(b.name, b.origin) + " overlap at " + what,
                        b.origin.empty() ? a.origin : b.origin});
    }
  }
  return issues;
}

}  // namespace facet::plc
