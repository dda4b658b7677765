// bench_tools: the measuring tools (caliper, pairs, line, blob) beside the classic OpenCV way of
// doing the same, on generated scenes with exact ground truth, under both blur models, printing
// the targets and the ratios. Seeds 1..N are the set the defaults were developed on;
// seeds 1000001..1000000+N are held out and were never looked at while tuning.
//
//   bench_tools [--smoke] [--scenes N] [--blob-scenes N] [--noise SIGMA]
//               [--only caliper|pairs|comb|line|blob]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>

#include "algorithms/measure/blob_analysis.hpp"
#include "algorithms/measure/caliper.hpp"
#include "algorithms/measure/line_measure.hpp"
#include "bench/tools/classic_tools.hpp"
#include "bench/tools/tool_scenes.hpp"

namespace {

using namespace facet;
using namespace facet::bench;
// Times are this thread's CPU time with OpenCV on one thread: on a machine shared with other
// work, wall-clock times of sub-millisecond calls measure the scheduler, not the code.
double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}
double ms(double a, double b) {
  return b - a;
}
double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return v.empty() ? NAN : std::sqrt(s / static_cast<double>(v.size()));
}
double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

struct SeedSet {
  const char* name;
  std::uint64_t first;
};
constexpr SeedSet kSets[] = {{"tune", 1}, {"held-out", 1000001}};
constexpr BlurModel kModels[] = {BlurModel::PixelGrid, BlurModel::Lens};

SceneNoise gNoise;  // --noise changes it (0 shows the estimators' bias alone)

// The Cramer-Rao bound of an unbiased edge position from the pixels under a caliper `width` px
// wide: each pixel carries b^2 F'(u)^2 / noise^2 of information, F' the blurred step's slope
// (Gaussian, sigma^2 = blur^2 + 1/12 for the pixel), so the width times the integral of F'^2,
// 1 / (2 sqrt(pi) sigma), gives sigma_e = noise / (b sqrt(width / (2 sqrt(pi) sigma))).
// No unbiased estimator does better on average; it is the yardstick for the noise part.
double positionBound(double contrast, double width) {
  const double sigma = std::sqrt(gNoise.blur * gNoise.blur + 1.0 / 12.0);
  return gNoise.noise / (contrast * std::sqrt(width / (2.0 * std::sqrt(CV_PI) * sigma)));
}

struct Timing {
  std::vector<double> facet, classic;
};

void caliperTable(int scenes, Timing& time) {
  std::printf("\nCaliper edge position, 40x20 px caliper, blur 0.9, noise %g, %d scenes per row\n",
              gNoise.noise, scenes);
  std::printf("%-11s %-9s | %12s %7s | %12s %7s | %6s | %9s | target\n", "blur model", "seeds",
              "facet RMS px", "misses", "classic RMS", "misses", "ratio", "CRLB px");
  for (BlurModel model : kModels)
    for (const SeedSet& set : kSets) {
      std::vector<double> ef, ec, bound;
      int mf = 0, mc = 0;
      for (int i = 0; i < scenes; ++i) {
        const EdgeScene s = makeEdgeScene(set.first + i, model, gNoise);
        bound.push_back(positionBound(s.contrast, s.rect.width));
        CaliperParams p;
        p.select = EdgeSelect::Strongest;
        const double t0 = cpuMs();
        const CaliperResult r = measureCaliper(s.image, MeasuringPath(s.rect), p);
        const double t1 = cpuMs();
        const auto c = classicCaliper(s.image, s.rect);
        const double t2 = cpuMs();
        time.facet.push_back(ms(t0, t1)), time.classic.push_back(ms(t1, t2));
        if (r.status.ok() && r.edges.size() == 1 && std::abs(r.edges[0].position - s.position) < 2)
          ef.push_back(r.edges[0].position - s.position);
        else
          ++mf;
        const auto best = std::max_element(c.begin(), c.end(), [](auto& a, auto& b) {
          return std::abs(a.derivative) < std::abs(b.derivative);
        });
        if (best != c.end() && std::abs(best->position - s.position) < 2)
          ec.push_back(best->position - s.position);
        else
          ++mc;
      }
      std::printf(
          "%-11s %-9s | %12.4f %7d | %12.4f %7d | %6.2f | %9.4f | <= 0.02 px and ratio "
          "<= 0.33\n",
          blurModelName(model), set.name, rms(ef), mf, rms(ec), mc, rms(ef) / rms(ec), rms(bound));
    }
}

void pairTable(int scenes) {
  std::printf("\nPair width (bars), 40x20 px caliper, blur 0.9, noise %g, %d scenes per row\n",
              gNoise.noise, scenes);
  std::printf("%-11s %-9s %-8s | %12s %12s %7s | %12s %7s | %6s | target\n", "blur model", "seeds",
              "bar px", "facet width", "centre", "misses", "classic", "misses", "ratio");
  for (double bar : {4.0, 8.0, 15.0})
    for (BlurModel model : kModels)
      for (const SeedSet& set : kSets) {
        std::vector<double> ew, ecen, ec;
        int mf = 0, mc = 0;
        for (int i = 0; i < scenes; ++i) {
          const BarScene s = makeBarScene(set.first + i, bar, model, gNoise);
          CaliperParams p;
          p.pairs = true;
          p.select = EdgeSelect::Strongest;
          p.polarity = s.light ? EdgePolarity::Rising : EdgePolarity::Falling;
          const CaliperResult r = measureCaliper(s.image, MeasuringPath(s.rect), p);
          if (r.status.ok() && r.pairs.size() == 1 && std::abs(r.pairs[0].width - s.width) < 2) {
            ew.push_back(r.pairs[0].width - s.width);
            ecen.push_back(r.pairs[0].position - s.centre);
          } else {
            ++mf;
          }
          // Classic: the strongest rising and the strongest falling peak.
          const auto c = classicCaliper(s.image, s.rect);
          const ClassicEdge *up = nullptr, *down = nullptr;
          for (const auto& e : c) {
            if (e.derivative > 0 && (!up || e.derivative > up->derivative)) up = &e;
            if (e.derivative < 0 && (!down || e.derivative < down->derivative)) down = &e;
          }
          if (up && down && std::abs(std::abs(up->position - down->position) - s.width) < 2)
            ec.push_back(std::abs(up->position - down->position) - s.width);
          else
            ++mc;
        }
        std::printf("%-11s %-9s %-8s | %12.4f %12.4f %7d | %12.4f %7d | %6.2f | width <= 0.03 px\n",
                    blurModelName(model), set.name,
                    (std::to_string(int(bar)) + "-" + std::to_string(int(bar) + 1)).c_str(),
                    rms(ew), rms(ecen), mf, rms(ec), mc, rms(ew) / rms(ec));
      }
}

// Combs of three teeth (bars of 4-5 px, gaps of 3-4 px) at blur 0.9 and at 1.5, where the teeth
// lie under five blur widths apart and the edges' blurs overlap. A comb is read when every edge
// and tooth is found (6 and 3); widths and pitches (distance between neighbouring teeth's
// middles) over those read. The classic caliper's edges are its derivative's peaks.
void combTable(int scenes) {
  const SceneNoise saved = gNoise;
  std::printf(
      "\nComb of three teeth (bars 4-5 px, gaps 3-4 px), 48x20 px caliper, noise %g, %d scenes per "
      "row\n",
      gNoise.noise, scenes);
  std::printf("%-11s %-9s %-4s | %6s %12s %12s | %6s %12s | %6s | target\n", "blur model", "seeds",
              "blur", "read", "facet width", "pitch", "read", "classic", "ratio");
  for (double blur : {0.9, 1.5})
    for (BlurModel model : kModels)
      for (const SeedSet& set : kSets) {
        gNoise.blur = blur;
        std::vector<double> ew, ep, ec;
        int readF = 0, readC = 0;
        for (int i = 0; i < scenes; ++i) {
          const CombScene s = makeCombScene(set.first + i, 3, 4.0, 3.0, model, gNoise);
          CaliperParams p;
          p.pairs = true;  // polarity any: the edges are all six, the pairs start at each tooth
          const CaliperResult r = measureCaliper(s.image, MeasuringPath(s.rect), p);
          if (r.status.ok() && r.edges.size() == 6 && r.pairs.size() == 3 &&
              (r.edges[0].amplitude > 0) == s.light) {
            ++readF;
            for (int k = 0; k < 3; ++k) ew.push_back(r.pairs[k].width - s.widths[k]);
            for (int k = 0; k < 2; ++k)
              ep.push_back(r.pairs[k + 1].position - r.pairs[k].position -
                           (s.centres[k + 1] - s.centres[k]));
          }
          // Classic: six peaks of alternating sign, the first of the teeth's polarity.
          const auto c = classicCaliper(s.image, s.rect);
          bool alternate = c.size() == 6;
          for (std::size_t k = 0; alternate && k < c.size(); ++k)
            alternate = (c[k].derivative > 0) == (s.light == (k % 2 == 0));
          if (alternate) {
            ++readC;
            for (int k = 0; k < 3; ++k)
              ec.push_back(c[2 * k + 1].position - c[2 * k].position - s.widths[k]);
          }
        }
        std::printf("%-11s %-9s %-4.1f | %6d %12.4f %12.4f | %6d %12.4f | %6.2f | -\n",
                    blurModelName(model), set.name, blur, readF, rms(ew), rms(ep), readC, rms(ec),
                    rms(ew) / rms(ec));
      }
  gNoise = saved;
}

void lineTable(int scenes, Timing& time) {
  std::printf(
      "\nLine, 200x16 px rectangle on a 200 px edge, blur 0.9, noise %g, %d scenes per row\n",
      gNoise.noise, scenes);
  std::printf("%-11s %-9s | %14s %13s %7s | %16s %7s | %6s | target\n", "blur model", "seeds",
              "facet angle deg", "end offset px", "misses", "fitLine angle", "misses", "ratio");
  for (BlurModel model : kModels)
    for (const SeedSet& set : kSets) {
      std::vector<double> af, ends, ac;
      int mf = 0, mc = 0;
      for (int i = 0; i < scenes; ++i) {
        const LineScene s = makeLineScene(set.first + i, model, gNoise);
        const double t0 = cpuMs();
        const LineMeasurement m = measureLine(s.image, s.rect);
        const double t1 = cpuMs();
        const ClassicLine c = cannyFitLine(s.image, s.rect);
        const double t2 = cpuMs();
        time.facet.push_back(ms(t0, t1)), time.classic.push_back(ms(t1, t2));
        const cv::Point2d nrm(-s.direction.y, s.direction.x);
        if (m.status.ok()) {
          double da = m.angle - s.angleDeg;
          da = std::remainder(da, 360.0);
          af.push_back(da);
          ends.push_back((m.p1 - s.point).dot(nrm));
          ends.push_back((m.p2 - s.point).dot(nrm));
        } else {
          ++mf;
        }
        if (c.ok) {
          const double cross = c.direction.x * s.direction.y - c.direction.y * s.direction.x;
          const double dot = c.direction.dot(s.direction);
          ac.push_back(std::atan2(cross, std::abs(dot)) * 180 / CV_PI * (dot < 0 ? -1 : 1));
        } else {
          ++mc;
        }
      }
      std::printf(
          "%-11s %-9s | %14.5f %13.4f %7d | %16.5f %7d | %6.2f | angle <= 0.005 deg, "
          "ends <= 0.02 px\n",
          blurModelName(model), set.name, rms(af), rms(ends), mf, rms(ac), mc, rms(af) / rms(ac));
    }
}

void blobTable(int scenes, Timing& time) {
  std::printf(
      "\nBlob, 1280x1024 frames of 24 discs r = 6-30 px, blur 0.9, noise %g, %d frames per "
      "row\n",
      gNoise.noise, scenes);
  std::printf("%-11s %-9s | %15s %11s | %15s %11s | target\n", "blur model", "seeds",
              "facet area RMS%", "exact count", "Otsu+CC area%", "exact count");
  for (BlurModel model : kModels)
    for (const SeedSet& set : kSets) {
      std::vector<double> ef, ec;
      int exactF = 0, exactC = 0;
      for (int i = 0; i < scenes; ++i) {
        const BlobScene s = makeBlobScene(set.first + i, model, gNoise);
        const double t0 = cpuMs();
        const BlobResult r = analyseBlobs(s.image);
        const double t1 = cpuMs();
        const auto c = otsuComponents(s.image);
        const double t2 = cpuMs();
        if (model == BlurModel::PixelGrid)
          time.facet.push_back(ms(t0, t1)), time.classic.push_back(ms(t1, t2));
        exactF += r.blobs.size() == s.radii.size();
        exactC += c.size() == s.radii.size();
        for (std::size_t k = 0; k < s.radii.size(); ++k) {
          const double truth = CV_PI * s.radii[k] * s.radii[k];
          for (const Blob& b : r.blobs)
            if (cv::norm(b.centroid - s.centres[k]) < s.radii[k] / 2)
              ef.push_back(100 * (b.area - truth) / truth);
          for (const ClassicBlob& b : c)
            if (cv::norm(b.centroid - s.centres[k]) < s.radii[k] / 2)
              ec.push_back(100 * (b.area - truth) / truth);
        }
      }
      std::printf(
          "%-11s %-9s | %15.3f %6d / %-3d | %15.3f %6d / %-3d | area <= 1%%, counts exact\n",
          blurModelName(model), set.name, rms(ef), exactF, scenes, rms(ec), exactC, scenes);
    }
}

}  // namespace

int main(int argc, char** argv) {
  int scenes = 300, lineScenes = 100, blobScenes = 6;
  std::string only;  // caliper, pairs, comb, line or blob: run that table alone
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke"))
      scenes = 10, lineScenes = 4, blobScenes = 1;
    else if (!std::strcmp(argv[i], "--scenes") && i + 1 < argc)
      scenes = std::atoi(argv[++i]), lineScenes = std::max(1, scenes / 3);
    else if (!std::strcmp(argv[i], "--blob-scenes") && i + 1 < argc)
      blobScenes = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc)
      only = argv[++i];
    else if (!std::strcmp(argv[i], "--noise") && i + 1 < argc)
      gNoise.noise = std::atof(argv[++i]);
    else {
      std::fprintf(stderr,
                   "usage: bench_tools [--smoke] [--scenes N] [--blob-scenes N] [--noise SIGMA]\n"
                   "                   [--only caliper|pairs|comb|line|blob]\n");
      return 1;
    }
  }
  std::printf(
      "bench_tools: generated scenes (both blur models: blurred on the pixel grid after "
      "integration, and a lens blurring before it, rendered 6x/4x supersampled)\n");
  cv::setNumThreads(1);
  Timing caliperTime, lineTime, blobTime;
  if (only.empty() || only == "caliper") caliperTable(scenes, caliperTime);
  if (only.empty() || only == "pairs") pairTable(scenes);
  if (only.empty() || only == "comb") combTable(std::max(1, scenes / 3));
  if (only.empty() || only == "line") lineTable(lineScenes, lineTime);
  if (only.empty() || only == "blob") blobTable(blobScenes, blobTime);
  std::printf(
      "\nTime per call, median thread CPU time, OpenCV on one thread (machine shared with other "
      "work)\n");
  std::printf("%-28s | %10s | %-30s %10s | %6s | target\n", "tool", "facet ms", "baseline", "ms",
              "ratio");
  std::printf("%-28s | %10.4f | %-30s %10.4f | %6.2f | <= 0.2 ms\n", "caliper 40x20",
              median(caliperTime.facet), "classic caliper", median(caliperTime.classic),
              median(caliperTime.facet) / median(caliperTime.classic));
  std::printf("%-28s | %10.4f | %-30s %10.4f | %6.2f | <= 0.5 ms\n", "line 200x16",
              median(lineTime.facet), "Canny + fitLine (whole image)", median(lineTime.classic),
              median(lineTime.facet) / median(lineTime.classic));
  std::printf("%-28s | %10.4f | %-30s %10.4f | %6.2f | ratio <= 1.5\n", "blob 1280x1024",
              median(blobTime.facet), "Otsu + connectedComponentsWithStats",
              median(blobTime.classic), median(blobTime.facet) / median(blobTime.classic));
  return 0;
}
