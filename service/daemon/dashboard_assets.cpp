#include "service/daemon/dashboard_assets.hpp"

#include <algorithm>

namespace facet::service {

const DashboardAsset* findDashboardAsset(std::string_view name) {
  const auto assets = dashboardAssets();
  const auto it = std::find_if(assets.begin(), assets.end(),
                               [&](const DashboardAsset& a) { return a.name == name; });
  return it == assets.end() ? nullptr : &*it;
}

}  // namespace facet::service
