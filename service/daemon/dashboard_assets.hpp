#pragma once
// The live dashboard's files (service/daemon/dashboard/), compiled into the binary so that an
// installed facetd serves its page without any asset folder and without the internet.

#include <span>
#include <string_view>

namespace facet::service {

struct DashboardAsset {
  std::string_view name;         // file name, e.g. "dashboard.js"
  std::string_view contentType;  // MIME type with charset
  std::string_view body;
};

// Every embedded file (generated at build time).
std::span<const DashboardAsset> dashboardAssets();

// The file called `name`, or nullptr.
const DashboardAsset* findDashboardAsset(std::string_view name);

}  // namespace facet::service
