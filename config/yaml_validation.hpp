#pragma once
// Checks a YAML tree against a format table (field_spec.hpp): mappings where mappings belong,
// types, ranges, enum names, required keys, unknown and duplicate keys (with the closest valid
// key suggested). It reports every problem it finds and never stops at the first.
//
// Rules that involve several values (step references, tolerances against their nominal, paths,
// PLC register collisions) belong to the loaders, which run after this.

#include <filesystem>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "config/diagnostic.hpp"
#include "config/field_spec.hpp"

namespace facet::config {

// `stepKinds` describes the items of StepList fields (empty when the format has none).
void validateObject(const YAML::Node& node, const ObjectSpec& spec,
                    const std::filesystem::path& file, Diagnostics& out,
                    const std::vector<StepKindSpec>& stepKinds = {});

// `%g` of a number, for messages.
std::string formatNumber(double value);

}  // namespace facet::config
