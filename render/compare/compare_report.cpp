#include "render/compare/compare_report.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace kf::render {

namespace {

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n') ? ' ' : c;
    }
  return out;
}

std::string metrics_line(const ImageMetrics& m) {
  char s[160];
  std::snprintf(s, sizeof s, "max %d, mean %.4g, RMSE %.4g, PSNR %.4g dB, over tolerance %.4g%%", m.max_abs,
                m.mean_abs, m.rmse, m.psnr, 100.0 * m.over_fraction);
  return s;
}

}  // namespace

std::string compare_json(const CompareRequest& r, const CompareResult& res) {
  using nlohmann::json;
  const CompareThresholds& t = r.thresholds;
  json j;
  j["actual"] = r.actual.string();
  j["reference"] = r.reference.string();
  j["thresholds"] = {{"tolerance_levels", t.tolerance},
                     {"max_fraction_over_tolerance", t.max_fraction},
                     {"max_mean_abs_levels", t.max_mean},
                     {"min_psnr_db", t.min_psnr}};
  j["frames_compared"] = res.frames.size();
  j["frames_failed"] = res.failed;
  j["frames_new"] = res.added;
  j["references_updated"] = res.updated;
  j["frames"] = json::array();
  for (const auto& f : res.frames) {
    const ImageMetrics& m = f.metrics;
    json e = {{"name", f.name},
              {"width", f.width},
              {"height", f.height},
              {"pass", f.pass},
              {"new", f.is_new},
              {"max_abs", m.max_abs},
              {"mean_abs", m.mean_abs},
              {"rmse", m.rmse},
              // null: identical frames (infinite PSNR)
              {"psnr_db", std::isfinite(m.psnr) ? json(m.psnr) : json(nullptr)},
              {"fraction_over_tolerance", m.over_fraction}};
    if (!f.pass) e["failure"] = f.why;
    if (!f.diff.empty()) {
      e["diff"] = f.diff;
      e["side_by_side"] = f.side;
    }
    j["frames"].push_back(e);
  }
  return j.dump(2) + "\n";
}

std::string compare_junit(const CompareRequest& r, const CompareResult& res) {
  const std::string suite = xml_escape("keyframe compare " + r.reference.filename().string());
  const std::string cls = xml_escape("compare." + r.reference.filename().string());
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  const std::string counts = " tests=\"" + std::to_string(res.frames.size()) + "\" failures=\"" +
                             std::to_string(res.failed) + "\" errors=\"0\" skipped=\"" + std::to_string(res.added) + "\"";
  x += "<testsuites name=\"keyframe compare\"" + counts + ">\n";
  x += "  <testsuite name=\"" + suite + "\"" + counts + ">\n";
  for (const auto& f : res.frames) {
    x += "    <testcase classname=\"" + cls + "\" name=\"" + xml_escape(f.name) + "\"";
    if (f.is_new) {
      x += ">\n      <skipped message=\"no reference frame; added by --update\"/>\n    </testcase>\n";
      continue;
    }
    if (f.pass) {
      x += "/>\n";
      continue;
    }
    x += ">\n      <failure message=\"" + xml_escape(f.why) + "\" type=\"ImageMismatch\">" +
         xml_escape(metrics_line(f.metrics) + (f.diff.empty() ? "" : "; heat map " + f.diff + ", side by side " + f.side)) +
         "</failure>\n    </testcase>\n";
  }
  x += "  </testsuite>\n</testsuites>\n";
  return x;
}

}  // namespace kf::render
