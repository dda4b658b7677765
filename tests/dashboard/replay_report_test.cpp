#include <gtest/gtest.h>

#include <sstream>

#include "service/daemon/replay_report.hpp"

namespace facet::service {
namespace {

ReplayedPart replayed(const std::string& file, Verdict verdict, const std::string& expected,
                      double diameter) {
  ReplayedPart r;
  r.result.source = "/data/" + file;
  r.result.serial = "S-" + file;
  r.result.verdict = verdict;
  r.result.expectedVerdict = expected;
  r.result.measurements.push_back({.name = "bore.diameter",
                                   .value = diameter,
                                   .unit = "mm",
                                   .nominal = 10.0,
                                   .tolMinus = 0.1,
                                   .tolPlus = 0.1,
                                   .checked = true,
                                   .pass = verdict == Verdict::Pass});
  r.result.timings = {{"bore", 2.0}};
  r.result.inspectionMs = 2.5;
  if (verdict != Verdict::Pass) r.thumbnailPng = {0x89, 'P', 'N', 'G'};
  return r;
}

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(ReplayReport, TablesChartsAndThumbnails) {
  ReplayReport report;
  report.title = "recipe 7 <bore>";
  report.parts = {replayed("a.png", Verdict::Pass, "pass", 10.0),
                  replayed("b.png", Verdict::Fail, "pass", 10.3),
                  replayed("c.png", Verdict::Fail, "fail", 9.7),
                  replayed("d.png", Verdict::Pass, "", 10.05)};
  std::ostringstream out;
  writeReplayReport(report, out);
  const std::string html = out.str();
  EXPECT_NE(html.find("recipe 7 &lt;bore&gt;"), std::string::npos);  // escaped
  EXPECT_EQ(occurrences(html, "<tr class=\"mismatch\">"), 1u);       // only b.png
  EXPECT_NE(html.find("unexpected verdicts 1"), std::string::npos);
  EXPECT_EQ(occurrences(html, "class=\"thumb\""), 2u);  // the two failed parts
  EXPECT_NE(html.find("data:image/png;base64,iVBORw=="), std::string::npos);
  EXPECT_EQ(occurrences(html, "<svg class=\"histogram\""), 1u);
  EXPECT_EQ(occurrences(html, "<svg class=\"trend\""), 1u);
  EXPECT_EQ(occurrences(html, "class=\"dot out\""), 2u);  // 10.3 and 9.7 lie outside
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http"), std::string::npos);  // self-contained
  EXPECT_NE(html.find("<td>total</td>"), std::string::npos);
}

// A 320 px thumbnail is too small to read: each links to its full picture, shown in the page
// (no script: a :target box), or to the recorded file when the report has no full picture.
TEST(ReplayReport, ThumbnailsLinkToTheFullPicture) {
  ReplayReport report;
  report.parts = {replayed("b.png", Verdict::Fail, "fail", 10.3),
                  replayed("c d.png", Verdict::Fail, "fail", 9.7)};
  report.parts[0].overlayPng = {0x89, 'P', 'N', 'G', 1};
  report.parts[0].result.recordedDefect = "big hole <1.2 mm>";
  std::ostringstream out;
  writeReplayReport(report, out);
  const std::string html = out.str();
  EXPECT_NE(html.find("<a class=\"enlarge\" href=\"#full-1\"><img class=\"thumb\""),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<div class=\"full\" id=\"full-1\">"), std::string::npos);
  EXPECT_NE(html.find("data:image/png;base64,iVBORwE="), std::string::npos);  // the full PNG
  EXPECT_NE(html.find(".full:target"), std::string::npos);
  // Without a full picture: the recorded file, its name escaped for a URL.
  EXPECT_NE(html.find("<a class=\"enlarge\" href=\"file:///data/c%20d.png\">"), std::string::npos)
      << html;
  EXPECT_EQ(html.find("<script"), std::string::npos);
  // The recording's defect beside its verdict.
  EXPECT_NE(html.find("fail <small>(big hole &lt;1.2 mm&gt;)</small>"), std::string::npos);
}

TEST(ReplayReport, UnexpectedVerdictNeedsAnExpectation) {
  PartResult p;
  p.verdict = Verdict::Fail;
  EXPECT_FALSE(verdictUnexpected(p));
  p.expectedVerdict = "fail";
  EXPECT_FALSE(verdictUnexpected(p));
  p.expectedVerdict = "pass";
  EXPECT_TRUE(verdictUnexpected(p));
}

}  // namespace
}  // namespace facet::service
