#include "service/daemon/replay_report.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "service/daemon/process_capability.hpp"

namespace facet::service {
namespace {

std::string escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string num(double v, int digits = 4) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string base64(const std::vector<unsigned char>& bytes) {
  static constexpr char table[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t n = (std::uint32_t{bytes[i]} << 16) |
                            (i + 1 < bytes.size() ? std::uint32_t{bytes[i + 1]} << 8 : 0) |
                            (i + 2 < bytes.size() ? std::uint32_t{bytes[i + 2]} : 0);
    out += table[(n >> 18) & 63];
    out += table[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[n & 63] : '=';
  }
  return out;
}

// A file:// link to a recorded image: absolute, with the characters a URL reserves escaped.
std::string fileUrl(const std::string& path) {
  std::error_code ec;
  const std::string absolute = std::filesystem::absolute(path, ec).string();
  std::string url = "file://";
  for (const unsigned char c : absolute.empty() ? path : absolute) {
    if (std::isalnum(c) || c == '/' || c == '.' || c == '-' || c == '_' || c == '~') {
      url += static_cast<char>(c);
    } else {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", c);
      url += buf;
    }
  }
  return url;
}

// The value range a chart shows: the data and the tolerance band, with a margin.
std::pair<double, double> chartRange(const Capability& c) {
  double lo = c.values.empty() ? 0 : *std::min_element(c.values.begin(), c.values.end());
  double hi = c.values.empty() ? 1 : *std::max_element(c.values.begin(), c.values.end());
  for (const auto& limit : {c.lower, c.upper, c.nominal})
    if (limit) lo = std::min(lo, *limit), hi = std::max(hi, *limit);
  if (!(hi > lo)) lo -= 1, hi += 1;
  const double margin = 0.1 * (hi - lo);
  return {lo - margin, hi + margin};
}

constexpr int kChartW = 420, kChartH = 180, kPad = 30;

std::string svgLine(double x1, double y1, double x2, double y2, const char* style) {
  return "<line x1=\"" + num(x1) + "\" y1=\"" + num(y1) + "\" x2=\"" + num(x2) + "\" y2=\"" +
         num(y2) + "\" class=\"" + style + "\"/>";
}

std::string svgText(double x, double y, const std::string& text, const char* anchor = "middle") {
  return "<text x=\"" + num(x) + "\" y=\"" + num(y) + "\" text-anchor=\"" + anchor + "\">" +
         escape(text) + "</text>";
}

// Histogram over the chart range (Sturges' bin count, at least 12 so a tight process still shows
// its shape), tolerance limits as red lines, nominal grey.
std::string histogramSvg(const Capability& c) {
  const auto [lo, hi] = chartRange(c);
  const int bins = std::clamp(
      static_cast<int>(std::ceil(std::log2(std::max<std::size_t>(c.values.size(), 1)))) + 1, 12,
      40);
  std::vector<int> counts(static_cast<std::size_t>(bins), 0);
  for (double v : c.values) {
    const int b = std::clamp(static_cast<int>((v - lo) / (hi - lo) * bins), 0, bins - 1);
    ++counts[static_cast<std::size_t>(b)];
  }
  const int most = std::max(1, *std::max_element(counts.begin(), counts.end()));
  const double left = kPad, right = kChartW - 10, top = 10, bottom = kChartH - kPad;
  auto x = [&](double v) { return left + (right - left) * (v - lo) / (hi - lo); };
  std::string s = "<svg class=\"histogram\" viewBox=\"0 0 " + std::to_string(kChartW) + " " +
                  std::to_string(kChartH) + "\" width=\"" + std::to_string(kChartW) +
                  "\" height=\"" + std::to_string(kChartH) + "\">";
  s += "<rect x=\"0\" y=\"0\" width=\"100%\" height=\"100%\" class=\"bg\"/>";
  if (c.lower && c.upper)
    s += "<rect x=\"" + num(x(*c.lower)) + "\" y=\"" + num(top) + "\" width=\"" +
         num(x(*c.upper) - x(*c.lower)) + "\" height=\"" + num(bottom - top) +
         "\" class=\"band\"/>";
  const double barW = (right - left) / bins;
  for (int b = 0; b < bins; ++b) {
    const double h = (bottom - top) * counts[static_cast<std::size_t>(b)] / most;
    s += "<rect x=\"" + num(left + b * barW + 1) + "\" y=\"" + num(bottom - h) + "\" width=\"" +
         num(std::max(barW - 2, 1.0)) + "\" height=\"" + num(h) + "\" class=\"bar\"/>";
  }
  s += svgLine(left, bottom, right, bottom, "axis");
  for (const auto& limit : {c.lower, c.upper})
    if (limit) {
      s += svgLine(x(*limit), top, x(*limit), bottom, "limit");
      s += svgText(x(*limit), bottom + 14, num(*limit));
    }
  if (c.nominal) s += svgLine(x(*c.nominal), top, x(*c.nominal), bottom, "nominal");
  s += svgText(left, top + 10, std::to_string(most), "end");
  return s + "</svg>";
}

// Values in part order, tolerance band shaded, out-of-band points red.
std::string trendSvg(const Capability& c) {
  const auto [lo, hi] = chartRange(c);
  const double left = 10, right = kChartW - 50, top = 10, bottom = kChartH - 20;
  const std::size_t n = c.values.size();
  auto x = [&](std::size_t i) {
    return n > 1 ? left + (right - left) * static_cast<double>(i) / static_cast<double>(n - 1)
                 : (left + right) / 2;
  };
  auto y = [&](double v) { return bottom - (bottom - top) * (v - lo) / (hi - lo); };
  std::string s = "<svg class=\"trend\" viewBox=\"0 0 " + std::to_string(kChartW) + " " +
                  std::to_string(kChartH) + "\" width=\"" + std::to_string(kChartW) +
                  "\" height=\"" + std::to_string(kChartH) + "\">";
  s += "<rect x=\"0\" y=\"0\" width=\"100%\" height=\"100%\" class=\"bg\"/>";
  if (c.lower && c.upper) {
    s += "<rect x=\"" + num(left) + "\" y=\"" + num(y(*c.upper)) + "\" width=\"" +
         num(right - left) + "\" height=\"" + num(y(*c.lower) - y(*c.upper)) +
         "\" class=\"band\"/>";
    for (const auto& limit : {c.lower, c.upper}) {
      s += svgLine(left, y(*limit), right, y(*limit), "limit");
      s += svgText(right + 4, y(*limit) + 4, num(*limit), "start");
    }
  }
  if (c.nominal) s += svgLine(left, y(*c.nominal), right, y(*c.nominal), "nominal");
  std::string points;
  for (std::size_t i = 0; i < n; ++i) points += num(x(i), 6) + "," + num(y(c.values[i]), 6) + " ";
  if (n > 1) s += "<polyline points=\"" + points + "\" class=\"series\"/>";
  for (std::size_t i = 0; i < n; ++i) {
    const double v = c.values[i];
    const bool inside = !(c.lower && c.upper) || (v >= *c.lower && v <= *c.upper);
    s += "<circle cx=\"" + num(x(i), 6) + "\" cy=\"" + num(y(v), 6) + "\" r=\"3\" class=\"" +
         (inside ? "dot" : "dot out") + "\"/>";
  }
  return s + "</svg>";
}

constexpr const char* kStyle = R"css(
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #1d2126; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 1.6em; border-bottom: 1px solid #ccd; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { padding: 0.25em 0.7em; border-bottom: 1px solid #e3e5e8; text-align: left; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
tr.mismatch td { background: #ffe0b2; font-weight: 600; }
.pass { color: #1f7a3a; } .fail { color: #c62828; } .error { color: #6b7280; }
.capable { color: #1f7a3a; } .incapable { color: #c62828; font-weight: 600; }
.charts { display: flex; flex-wrap: wrap; gap: 1em; margin-bottom: 1em; }
.check h3 { font-size: 1em; margin: 1em 0 0.3em; }
svg text { font: 11px system-ui, sans-serif; fill: #444; }
svg .bg { fill: #f7f8fa; } svg .band { fill: #c8ecd2; } svg .bar { fill: #3b78c4; }
svg .axis { stroke: #888; } svg .limit { stroke: #c62828; stroke-width: 1.5; }
svg .nominal { stroke: #555; stroke-dasharray: 4 3; }
svg .series { fill: none; stroke: #3b78c4; stroke-width: 1.5; }
svg .dot { fill: #3b78c4; } svg .dot.out { fill: #c62828; }
.thumbs { display: flex; flex-wrap: wrap; gap: 1em; }
figure { margin: 0; } figcaption { font-size: 0.9em; max-width: 320px; }
a.enlarge { cursor: zoom-in; }
.full { display: none; } .full:target { display: block; position: fixed; inset: 0; z-index: 9;
  background: rgba(0, 0, 0, 0.85); padding: 2em; text-align: center; overflow: auto; }
.full img { max-width: 100%; } .full a { color: #fff; display: block; margin-bottom: 0.5em; }
.summary span { margin-right: 1.5em; }
)css";

void verdictTable(const ReplayReport& r, std::ostream& out) {
  out << "<h2>Verdicts</h2>\n<table id=\"verdicts\"><tr><th>#</th><th>image</th><th>serial</th>"
         "<th>verdict</th><th>expected</th><th>failed checks / error</th><th>ms</th></tr>\n";
  for (std::size_t i = 0; i < r.parts.size(); ++i) {
    const PartResult& p = r.parts[i].result;
    const std::string verdict = verdictName(p.verdict);
    std::string why = p.error;
    for (const auto& f : p.failedChecks) why += (why.empty() ? "" : ", ") + f;
    const auto file = p.source.substr(p.source.find_last_of('/') + 1);
    out << "<tr" << (verdictUnexpected(p) ? " class=\"mismatch\"" : "") << "><td class=\"n\">"
        << i + 1 << "</td><td>" << escape(file) << "</td><td>" << escape(p.serial)
        << "</td><td class=\"" << verdict << "\">" << verdict << "</td><td>"
        << escape(p.expectedVerdict.empty() ? "–" : p.expectedVerdict)
        << (p.recordedDefect.empty() ? "" : " <small>(" + escape(p.recordedDefect) + ")</small>")
        << "</td><td>" << escape(why) << "</td><td class=\"n\">" << num(p.inspectionMs, 3)
        << "</td></tr>\n";
  }
  out << "</table>\n";
}

void capabilityTable(const std::vector<Capability>& caps, std::ostream& out) {
  out << "<h2>Process capability</h2>\n<table id=\"capability\"><tr><th>value</th><th>unit</th>"
         "<th>n</th><th>mean</th><th>sigma</th><th>lower</th><th>upper</th><th>Cp</th>"
         "<th>index</th><th>value</th></tr>\n";
  auto opt = [](const std::optional<double>& v) { return v ? num(*v) : std::string("–"); };
  for (const auto& c : caps) {
    const char* cls = !c.cpk ? "" : *c.cpk >= 1.33 ? "capable" : "incapable";
    out << "<tr><td>" << escape(c.name) << "</td><td>" << escape(c.unit) << "</td><td class=\"n\">"
        << c.count << "</td><td class=\"n\">" << num(c.mean, 6) << "</td><td class=\"n\">"
        << num(c.sigma, 3) << "</td><td class=\"n\">" << opt(c.lower) << "</td><td class=\"n\">"
        << opt(c.upper) << "</td><td class=\"n\">" << opt(c.cp) << "</td><td>"
        << (c.index.empty() ? "–" : c.index) << "</td><td class=\"n " << cls << "\">" << opt(c.cpk)
        << "</td></tr>\n";
  }
  out << "</table>\n<p>Cp = (upper &minus; lower) / 6&sigma;, Cpk = min(upper &minus; mean, mean "
         "&minus; lower) / 3&sigma;. Where a limit is the quantity's natural bound (a position "
         "error or roundness cannot fall below 0, a score cannot exceed 1) the band is one-sided: "
         "the index is Cpu = (upper &minus; mean) / 3&sigma; or Cpl = (mean &minus; lower) / "
         "3&sigma;, without Cp. An index &ge; 1.33 is shown green. A value without a tolerance has "
         "no index.</p>\n";
}

void timingTable(const ReplayReport& r, std::ostream& out) {
  struct Stat {
    std::vector<double> ms;
  };
  std::vector<std::pair<std::string, Stat>> steps;
  auto add = [&](const std::string& name, double ms) {
    auto it = std::find_if(steps.begin(), steps.end(), [&](auto& s) { return s.first == name; });
    if (it == steps.end()) it = steps.insert(steps.end(), {name, {}});
    it->second.ms.push_back(ms);
  };
  for (const auto& part : r.parts) {
    for (const auto& t : part.result.timings) add(t.step, t.ms);
    add("total", part.result.inspectionMs);
  }
  out << "<h2>Time per step</h2>\n<table id=\"timing\"><tr><th>step</th><th>n</th><th>mean ms"
         "</th><th>median ms</th><th>max ms</th></tr>\n";
  for (auto& [name, stat] : steps) {
    auto ms = stat.ms;
    std::sort(ms.begin(), ms.end());
    double sum = 0;
    for (double v : ms) sum += v;
    out << "<tr><td>" << escape(name) << "</td><td class=\"n\">" << ms.size()
        << "</td><td class=\"n\">" << num(sum / static_cast<double>(ms.size()), 3)
        << "</td><td class=\"n\">" << num(ms[ms.size() / 2], 3) << "</td><td class=\"n\">"
        << num(ms.back(), 3) << "</td></tr>\n";
  }
  out << "</table>\n";
}

}  // namespace

bool verdictUnexpected(const PartResult& part) {
  return !part.expectedVerdict.empty() && part.expectedVerdict != verdictName(part.verdict);
}

void writeReplayReport(const ReplayReport& r, std::ostream& out) {
  std::map<std::string, int> counts;
  int unexpected = 0;
  std::vector<PartResult> results;
  for (const auto& part : r.parts) {
    ++counts[verdictName(part.result.verdict)];
    unexpected += verdictUnexpected(part.result) ? 1 : 0;
    results.push_back(part.result);
  }
  const auto caps = processCapability(results);

  out << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
         "<link rel=\"icon\" href=\"data:,\"><title>facet replay: "
      << escape(r.title) << "</title>\n<style>" << kStyle << "</style></head>\n<body>\n";
  out << "<h1>Replay report: " << escape(r.title) << "</h1>\n<p>recipe <code>"
      << escape(r.recipeFile) << "</code> over <code>" << escape(r.imagesFolder) << "</code>, "
      << num(r.mmPerPixel) << " mm/px, generated " << escape(r.generatedAt) << "</p>\n";
  out << "<p class=\"summary\" id=\"summary\"><span>parts " << r.parts.size()
      << "</span><span class=\"pass\">pass " << counts["pass"]
      << "</span><span class=\"fail\">fail " << counts["fail"]
      << "</span><span class=\"error\">error " << counts["error"] << "</span><span"
      << (unexpected ? " class=\"fail\"" : "") << ">unexpected verdicts " << unexpected
      << "</span></p>\n";
  verdictTable(r, out);
  capabilityTable(caps, out);
  out << "<h2>Measured values</h2>\n";
  for (const auto& c : caps) {
    out << "<div class=\"check\"><h3>" << escape(c.name) << " [" << escape(c.unit) << "]";
    if (c.lower && c.upper) out << " tolerance " << num(*c.lower) << " … " << num(*c.upper);
    out << "</h3>\n<div class=\"charts\">" << histogramSvg(c) << trendSvg(c) << "</div></div>\n";
  }
  out << "<h2 id=\"failed\">Failed parts</h2>\n<div class=\"thumbs\">\n";
  int shown = 0;
  for (const auto& part : r.parts) {
    const PartResult& p = part.result;
    if (p.verdict == Verdict::Pass || part.thumbnailPng.empty()) continue;
    std::string why = p.error;
    for (const auto& f : p.failedChecks) why += (why.empty() ? "" : ", ") + f;
    // The thumbnail is too small to read: it links to the full picture, shown in the page by
    // CSS alone (:target) since the report has no script, or to the recorded file.
    const std::string id = "full-" + std::to_string(shown + 1);
    const std::string href = part.overlayPng.empty() ? fileUrl(p.source) : "#" + id;
    out << "<figure><a class=\"enlarge\" href=\"" << escape(href)
        << "\"><img class=\"thumb\" alt=\"" << escape(p.source) << "\" src=\"data:image/png;base64,"
        << base64(part.thumbnailPng) << "\"></a><figcaption>"
        << escape(p.source.substr(p.source.find_last_of('/') + 1)) << " " << escape(p.serial)
        << ": " << verdictName(p.verdict) << " — " << escape(why) << " <a href=\""
        << escape(fileUrl(p.source)) << "\">recorded image</a></figcaption></figure>\n";
    if (!part.overlayPng.empty())
      out << "<div class=\"full\" id=\"" << id << "\"><a href=\"#failed\">close</a><img alt=\""
          << escape(p.source) << "\" src=\"data:image/png;base64," << base64(part.overlayPng)
          << "\"></div>\n";
    ++shown;
  }
  if (!shown) out << "<p>none</p>\n";
  out << "</div>\n";
  timingTable(r, out);
  out << "</body></html>\n";
}

}  // namespace facet::service
