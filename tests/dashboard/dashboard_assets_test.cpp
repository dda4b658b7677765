// The dashboard compiled into facetd: every file is there, and nothing is fetched from elsewhere.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "service/daemon/dashboard_assets.hpp"

namespace facet::service {
namespace {

TEST(DashboardAssets, PageAndItsFilesAreEmbedded) {
  const auto* index = findDashboardAsset("index.html");
  ASSERT_NE(index, nullptr);
  EXPECT_EQ(index->contentType, "text/html; charset=utf-8");
  // Every file the page links is embedded too.
  const std::string html(index->body);
  const std::regex linked(R"re((?:src|href)="/dashboard/([^"]+)")re");
  int links = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), linked);
       it != std::sregex_iterator(); ++it, ++links)
    EXPECT_NE(findDashboardAsset((*it)[1].str()), nullptr) << (*it)[1];
  EXPECT_EQ(links, 2);  // the stylesheet and the script
  ASSERT_NE(findDashboardAsset("dashboard.js"), nullptr);
  EXPECT_EQ(findDashboardAsset("dashboard.js")->contentType, "text/javascript; charset=utf-8");
  EXPECT_EQ(findDashboardAsset("missing.js"), nullptr);
}

TEST(DashboardAssets, NothingComesFromTheInternet) {
  for (const auto& asset : dashboardAssets()) {
    const std::string body(asset.body);
    EXPECT_FALSE(body.empty()) << asset.name;
    EXPECT_EQ(body.find("http://"), std::string::npos) << asset.name;
    EXPECT_EQ(body.find("https://"), std::string::npos) << asset.name;
    EXPECT_EQ(body.find("//cdn"), std::string::npos) << asset.name;
  }
}

TEST(DashboardAssets, TokenIsAskedNotEmbedded) {
  const std::string js(findDashboardAsset("dashboard.js")->body);
  EXPECT_NE(js.find("window.prompt('Station token"), std::string::npos);
  EXPECT_EQ(js.find("localStorage"), std::string::npos);
  EXPECT_EQ(js.find("sessionStorage"), std::string::npos);
}

}  // namespace
}  // namespace facet::service
