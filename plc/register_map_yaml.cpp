#include "plc/register_map_yaml.hpp"

#include <fstream>
#include <set>
#include <sstream>

namespace facet::plc {
namespace {

std::string where(const std::string& file, const YAML::Mark& mark) {
  if (mark.is_null()) return file;
  return file + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

[[noreturn]] void fail(const std::string& file, const YAML::Node& node, const std::string& what) {
  throw RegisterMapError(where(file, node.Mark()) + ": " + what);
}

void requireMap(const std::string& file, const YAML::Node& node, const std::string& what) {
  if (!node.IsMap()) fail(file, node, what + " must be a mapping");
}

// Rejects keys outside `known`, naming the key's own position.
void rejectUnknownKeys(const std::string& file, const YAML::Node& node,
                       const std::set<std::string>& known, const std::string& what) {
  for (const auto& entry : node) {
    const std::string key = entry.first.Scalar();
    if (!known.contains(key)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      fail(file, entry.first,
           "unknown key '" + key + "' in " + what + " (expected one of: " + list + ")");
    }
  }
}

int toInt(const std::string& file, const YAML::Node& node, const std::string& what) {
  if (!node.IsScalar()) fail(file, node, what + " must be an integer");
  try {
    return node.as<int>();
  } catch (const YAML::Exception&) {
    fail(file, node, what + " must be an integer, not '" + node.Scalar() + "'");
  }
}

double toDouble(const std::string& file, const YAML::Node& node, const std::string& what) {
  if (!node.IsScalar()) fail(file, node, what + " must be a number");
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    fail(file, node, what + " must be a number, not '" + node.Scalar() + "'");
  }
}

std::string toText(const std::string& file, const YAML::Node& node, const std::string& what) {
  if (!node.IsScalar()) fail(file, node, what + " must be a string");
  return node.Scalar();
}

// {coil: N} | {register: N} | {register: N, bit: B}
Location parseLocation(const std::string& file, const YAML::Node& node, const std::string& name) {
  requireMap(file, node, name);
  rejectUnknownKeys(file, node, {"coil", "register", "bit"}, name);
  Location at;
  at.origin = where(file, node.Mark());
  const bool hasCoil = static_cast<bool>(node["coil"]);
  const bool hasRegister = static_cast<bool>(node["register"]);
  if (hasCoil == hasRegister) fail(file, node, name + " needs exactly one of 'coil' or 'register'");
  if (hasCoil) {
    at.table = Table::Coil;
    at.address = toInt(file, node["coil"], name + ".coil");
  } else {
    at.table = Table::HoldingRegister;
    at.address = toInt(file, node["register"], name + ".register");
  }
  if (node["bit"]) at.bit = toInt(file, node["bit"], name + ".bit");
  return at;
}

struct SignalField {
  const char* key;
  std::optional<Location>* target;
};

void parseSignals(const std::string& file, const YAML::Node& node, const std::string& section,
                  const std::vector<SignalField>& fields) {
  requireMap(file, node, section);
  std::set<std::string> known;
  for (const auto& f : fields) known.insert(f.key);
  rejectUnknownKeys(file, node, known, section);
  for (const auto& f : fields)
    if (const YAML::Node value = node[f.key])
      *f.target = parseLocation(file, value, section + "." + f.key);
}

ResultOutput parseResult(const std::string& file, const YAML::Node& node, std::size_t index) {
  const std::string what = "results[" + std::to_string(index) + "]";
  requireMap(file, node, what);
  rejectUnknownKeys(file, node, {"name", "register", "type", "factor", "word_order"}, what);
  ResultOutput output;
  output.origin = where(file, node.Mark());
  if (!node["name"]) fail(file, node, what + " needs a 'name'");
  output.name = toText(file, node["name"], what + ".name");
  const std::string named = "result '" + output.name + "'";
  if (!node["register"]) fail(file, node, named + " needs a 'register'");
  output.address = toInt(file, node["register"], named + ".register");
  if (const YAML::Node type = node["type"]) {
    const auto parsed = parseValueType(toText(file, type, named + ".type"));
    if (!parsed)
      fail(file, type,
           named + ": unknown type '" + type.Scalar() +
               "' (expected int16, int32, scaled_int16, scaled_int32, float32)");
    output.type = *parsed;
  }
  if (const YAML::Node factor = node["factor"]) {
    if (output.type != ValueType::ScaledInt16 && output.type != ValueType::ScaledInt32)
      fail(file, factor, named + ": 'factor' applies to scaled_int16 / scaled_int32 only");
    output.factor = toDouble(file, factor, named + ".factor");
  } else if (output.type == ValueType::ScaledInt16 || output.type == ValueType::ScaledInt32) {
    fail(file, node, named + ": a scaled type needs a 'factor'");
  }
  if (const YAML::Node order = node["word_order"]) {
    const auto parsed = parseWordOrder(toText(file, order, named + ".word_order"));
    if (!parsed)
      fail(file, order,
           named + ": unknown word_order '" + order.Scalar() +
               "' (expected ABCD, CDAB, BADC, DCBA)");
    output.wordOrder = *parsed;
  }
  return output;
}

}  // namespace

RegisterMap parseRegisterMap(const YAML::Node& node, const std::string& fileName) {
  if (!node || node.IsNull()) throw RegisterMapError(fileName + ": the register map is empty");
  requireMap(fileName, node, "the register map");
  rejectUnknownKeys(fileName, node, {"address_base", "control", "status", "results"},
                    "the register map");
  RegisterMap map;
  if (const YAML::Node base = node["address_base"]) {
    map.addressBase = toInt(fileName, base, "address_base");
    if (map.addressBase != 0 && map.addressBase != 1)
      fail(fileName, base, "address_base must be 0 or 1");
  }
  if (const YAML::Node control = node["control"]) {
    auto& c = map.control;
    parseSignals(fileName, control, "control",
                 {{"trigger", &c.trigger},
                  {"result_ack", &c.resultAck},
                  {"recipe_select", &c.recipeSelect},
                  {"enable", &c.enable}});
  }
  if (const YAML::Node status = node["status"]) {
    auto& s = map.status;
    parseSignals(fileName, status, "status",
                 {{"ready", &s.ready},
                  {"busy", &s.busy},
                  {"result_valid", &s.resultValid},
                  {"pass", &s.pass},
                  {"completed_toggle", &s.completedToggle},
                  {"missed_trigger", &s.missedTrigger},
                  {"error", &s.error},
                  {"error_code", &s.errorCode},
                  {"heartbeat", &s.heartbeat},
                  {"inspection_counter", &s.inspectionCounter},
                  {"active_recipe", &s.activeRecipe}});
  }
  if (const YAML::Node results = node["results"]) {
    if (!results.IsSequence()) fail(fileName, results, "results must be a list");
    for (std::size_t i = 0; i < results.size(); ++i)
      map.results.push_back(parseResult(fileName, results[i], i));
  }

  const auto issues = map.validate();
  if (!issues.empty()) {
    std::string message;
    // "file:line:column: message" per issue, like every other error of the parser.
    for (const auto& issue : issues) {
      if (!message.empty()) message.push_back('\n');
      if (issue.origin.empty()) message.append(fileName).append(": ");
      message.append(describe(issue));
    }
    throw RegisterMapError(message);
  }
  return map;
}

RegisterMap parseRegisterMapText(const std::string& text, const std::string& fileName) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw RegisterMapError(where(fileName, e.mark) + ": " + e.msg);
  } catch (const YAML::Exception& e) {
    throw RegisterMapError(fileName + ": " + e.what());
  }
  return parseRegisterMap(root, fileName);
}

RegisterMap loadRegisterMap(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw RegisterMapError(path + ": cannot read the register map file");
  std::ostringstream text;
  text << in.rdbuf();
  return parseRegisterMapText(text.str(), path);
}

}  // namespace facet::plc
