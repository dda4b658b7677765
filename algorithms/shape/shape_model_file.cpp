#include "algorithms/shape/shape_model_file.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

namespace facet {
namespace {

constexpr std::array<char, 8> kMagic = {'F', 'A', 'C', 'E', 'T', 'S', 'H', 'M'};
constexpr std::size_t kHeaderSize = kMagic.size() + sizeof(std::uint32_t) + sizeof(std::uint64_t);
constexpr std::uint32_t kMaxPoints = 10'000'000;  // far above any real model: guards bad counts
constexpr std::uint32_t kMaxLevels = 16;
constexpr int kMaxTemplateSide = 1 << 14;  // pixels
constexpr double kMaxScale = 10.0;         // the search's border grows with radius * scale
constexpr double kMaxSearchSamples = 1e6;  // angle or scale steps per search range
constexpr double kMaxStepRatio = 4.0;      // a level's angle step over the one below
// findSearchSymmetries gives at most 3 of level 0 and 3 of the top level; each costs every search
// a turned pose to score.
constexpr std::uint32_t kMaxSymmetries = 16;
constexpr std::uint32_t kMaxTrackedPeriods = 16;

std::uint64_t fnv1a(const char* data, std::size_t size) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

// Little-endian on every machine we ship to (x86-64, aarch64); values are copied bytewise.
class Writer {
 public:
  template <typename T>
  void put(T value) {
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void putPoints(const std::vector<ShapePoint>& points) {
    put(static_cast<std::uint32_t>(points.size()));
    for (const auto& p : points) {
      put(p.position.x), put(p.position.y), put(p.direction.x), put(p.direction.y);
    }
  }
  [[nodiscard]] const std::vector<char>& bytes() const { return bytes_; }

 private:
  std::vector<char> bytes_;
};

class Reader {
 public:
  Reader(const char* data, std::size_t size, const std::string& file)
      : data_(data), size_(size), file_(file) {}
  template <typename T>
  T get() {
    if (size_ - offset_ < sizeof(T)) fail("truncated model data");
    T value;
    std::memcpy(&value, data_ + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  std::vector<ShapePoint> getPoints() {
    const auto n = get<std::uint32_t>();
    if (n > kMaxPoints || n * 16ull > size_ - offset_) fail("corrupt point count");
    std::vector<ShapePoint> points(n);
    for (auto& p : points) {
      p.position.x = get<float>(), p.position.y = get<float>();
      p.direction.x = get<float>(), p.direction.y = get<float>();
    }
    return points;
  }
  [[nodiscard]] bool atEnd() const { return offset_ == size_; }
  [[noreturn]] void fail(const std::string& why) const {
    throw ShapeModelFileError(file_ + ": " + why);
  }

 private:
  const char* data_;
  std::size_t size_;
  std::size_t offset_ = 0;
  std::string file_;
};

bool finitePoint(const cv::Point2f& p, double limit) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::abs(p.x) <= limit &&
         std::abs(p.y) <= limit;
}

// Model points lie on the template, relative to the reference point: farther out than the
// template's size from it is not a trained model.
bool finitePoints(const std::vector<ShapePoint>& points, double extent) {
  return std::all_of(points.begin(), points.end(), [extent](const ShapePoint& p) {
    return finitePoint(p.position, extent) && finitePoint(p.direction, 2.0);
  });
}

// A file can pass its checksum and still hold values no search can use (crafted by hand, or
// damaged before the checksum was written): NaN poses, zero or tiny search steps that make
// findShapeModel loop (nearly) for ever or allocate without bound, points that overflow pixel
// indices. Why a model is refused, or "" when it is usable.
std::string implausibility(const ShapeModel& m) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  if (m.templateSize.width <= 0 || m.templateSize.height <= 0 ||
      m.templateSize.width > kMaxTemplateSide || m.templateSize.height > kMaxTemplateSide)
    return "template size";
  for (double v : {m.referencePoint.x, m.referencePoint.y, m.angleStart, m.angleExtent, m.scaleMin,
                   m.scaleMax, m.minContrast, m.contrastLow, m.contrastHigh})
    if (!std::isfinite(v)) return "a value is not a finite number";
  if (!(m.angleExtent >= 0.0 && m.angleExtent <= kTwoPi + 1e-6)) return "angle extent";
  if (std::abs(m.angleStart) > 2.0 * kTwoPi) return "angle start";
  if (!(m.scaleMin > 0.0) || !(m.scaleMax >= m.scaleMin) || m.scaleMax > kMaxScale)
    return "scale range";
  if (std::abs(m.referencePoint.x) > 2.0 * kMaxTemplateSide ||
      std::abs(m.referencePoint.y) > 2.0 * kMaxTemplateSide)
    return "reference point";
  const double extent = m.templateSize.width + m.templateSize.height +
                        std::abs(m.referencePoint.x) + std::abs(m.referencePoint.y);
  for (const auto& level : m.levels) {
    if (!(level.angleStep > 0.0) || !(kTwoPi / level.angleStep <= kMaxSearchSamples) ||
        level.angleStep > kTwoPi)
      return "angle step";
    if (!(level.scaleStep >= 0.0) || !(level.scaleStep <= kMaxScale) ||
        (level.scaleStep > 0.0 && (m.scaleMax - m.scaleMin) / level.scaleStep > kMaxSearchSamples))
      return "scale step";
    if (!finitePoints(level.points, extent)) return "point coordinates";
  }
  // Each level's angle step is about twice the one below (atan(1 / R) of a radius halved, or a
  // given step doubled): never more than kMaxStepRatio times. The search looks two steps of a
  // level wide on the level below, in that level's steps: a file whose level 1 step was 2,750
  // of level 0's made one search of a 48x40 image take six minutes.
  for (std::size_t l = 1; l < m.levels.size(); ++l)
    if (m.levels[l].angleStep > kMaxStepRatio * m.levels[l - 1].angleStep) return "angle step";
  if (!finitePoints(m.finePoints, extent)) return "point coordinates";
  // A turn's centre may lie off the template (a few degrees' turn with a shift), never far off.
  for (const ModelSymmetry& sym : m.symmetries)
    if (!std::isfinite(sym.angle) || std::abs(sym.angle) > kTwoPi ||
        !(std::abs(sym.centre.x) <= 4.0 * kMaxTemplateSide) ||
        !(std::abs(sym.centre.y) <= 4.0 * kMaxTemplateSide) ||
        !(sym.score >= 0.0 && sym.score <= 1.0 + 1e-6))
      return "symmetry";
  for (const ModelPeriod& period : m.trackedPeriods)
    if (!(std::abs(period.shift.x) <= 4.0 * kMaxTemplateSide) ||
        !(std::abs(period.shift.y) <= 4.0 * kMaxTemplateSide) ||
        !(period.score >= 0.0 && period.score <= 1.0 + 1e-6))
      return "period";
  return "";
}

}  // namespace

void saveShapeModel(const ShapeModel& model, const std::filesystem::path& path) {
  if (model.empty()) throw ShapeModelFileError(path.string() + ": cannot save an empty model");
  Writer w;
  w.put<std::int32_t>(model.templateSize.width);
  w.put<std::int32_t>(model.templateSize.height);
  for (double v :
       {model.referencePoint.x, model.referencePoint.y, model.angleStart, model.angleExtent,
        model.scaleMin, model.scaleMax, model.minContrast, model.contrastLow, model.contrastHigh})
    w.put(v);
  w.put(static_cast<std::uint32_t>(model.levels.size()));
  for (const auto& level : model.levels) {
    w.put(level.angleStep);
    w.put(level.scaleStep);
    w.putPoints(level.points);
  }
  w.putPoints(model.finePoints);
  w.put(static_cast<std::uint8_t>(model.edgeEstimator == EdgeEstimator::ProfileFit ? 0 : 1));
  w.put(static_cast<std::uint32_t>(model.symmetries.size()));
  for (const ModelSymmetry& sym : model.symmetries)
    w.put(sym.angle), w.put(sym.centre.x), w.put(sym.centre.y), w.put(sym.score);
  w.put(static_cast<std::uint32_t>(model.trackedPeriods.size()));
  for (const ModelPeriod& period : model.trackedPeriods)
    w.put(period.shift.x), w.put(period.shift.y), w.put(period.score);

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw ShapeModelFileError(path.string() + ": cannot open for writing");
  const auto& payload = w.bytes();
  const std::uint64_t size = payload.size();
  const std::uint64_t checksum = fnv1a(payload.data(), payload.size());
  out.write(kMagic.data(), kMagic.size());
  out.write(reinterpret_cast<const char*>(&kShapeModelFileVersion), sizeof(std::uint32_t));
  out.write(reinterpret_cast<const char*>(&size), sizeof(size));
  out.write(payload.data(), static_cast<std::streamsize>(payload.size()));
  out.write(reinterpret_cast<const char*>(&checksum), sizeof(checksum));
  if (!out.flush()) throw ShapeModelFileError(path.string() + ": write failed");
}

ShapeModel loadShapeModel(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ShapeModelFileError(name + ": cannot open shape model file");
  const std::vector<char> file{std::istreambuf_iterator<char>(in),
                               std::istreambuf_iterator<char>()};
  if (file.size() < kMagic.size() || std::memcmp(file.data(), kMagic.data(), kMagic.size()) != 0)
    throw ShapeModelFileError(name + ": not a facet shape model file (bad magic)");
  if (file.size() < kHeaderSize)
    throw ShapeModelFileError(name + ": truncated shape model file (incomplete header)");
  std::uint32_t version = 0;
  std::uint64_t size = 0;
  std::memcpy(&version, file.data() + kMagic.size(), sizeof(version));
  std::memcpy(&size, file.data() + kMagic.size() + sizeof(version), sizeof(size));
  if (version < 1 || version > kShapeModelFileVersion)
    throw ShapeModelFileError(name + ": unsupported shape model file version " +
                              std::to_string(version) + " (this build reads versions 1 to " +
                              std::to_string(kShapeModelFileVersion) + ")");
  if (file.size() - kHeaderSize < sizeof(std::uint64_t) ||
      size > file.size() - kHeaderSize - sizeof(std::uint64_t))
    throw ShapeModelFileError(name + ": truncated shape model file (" +
                              std::to_string(file.size()) + " bytes, header announces " +
                              std::to_string(kHeaderSize + size + 8) + ")");
  if (file.size() != kHeaderSize + size + sizeof(std::uint64_t))
    throw ShapeModelFileError(name + ": corrupt shape model file (trailing bytes)");
  const char* payload = file.data() + kHeaderSize;
  std::uint64_t checksum = 0;
  std::memcpy(&checksum, payload + size, sizeof(checksum));
  if (checksum != fnv1a(payload, size))
    throw ShapeModelFileError(name + ": corrupt shape model file (checksum mismatch)");

  Reader r(payload, size, name);
  ShapeModel model;
  model.templateSize.width = r.get<std::int32_t>();
  model.templateSize.height = r.get<std::int32_t>();
  for (double* v : {&model.referencePoint.x, &model.referencePoint.y, &model.angleStart,
                    &model.angleExtent, &model.scaleMin, &model.scaleMax, &model.minContrast,
                    &model.contrastLow, &model.contrastHigh})
    *v = r.get<double>();
  const auto levels = r.get<std::uint32_t>();
  if (levels == 0 || levels > kMaxLevels) r.fail("corrupt level count");
  for (std::uint32_t i = 0; i < levels; ++i) {
    ShapeLevel level;
    level.angleStep = r.get<double>();
    level.scaleStep = r.get<double>();
    level.points = r.getPoints();
    model.levels.push_back(std::move(level));
  }
  model.finePoints = r.getPoints();
  // Version 1 has no estimator: its models were searched with the profile fit.
  if (version >= 2) {
    const auto estimator = r.get<std::uint8_t>();
    if (estimator > 1) r.fail("corrupt edge estimator");
    model.edgeEstimator =
        estimator == 0 ? EdgeEstimator::ProfileFit : EdgeEstimator::FacetZeroCrossing;
  }
  if (version >= 3) {
    const auto count = r.get<std::uint32_t>();
    if (count > kMaxSymmetries) r.fail("corrupt symmetry count");
    model.symmetries.resize(count);
    for (ModelSymmetry& sym : model.symmetries) {
      sym.angle = r.get<double>();
      sym.centre.x = r.get<double>(), sym.centre.y = r.get<double>();
      sym.score = r.get<double>();
    }
  }
  if (version >= 4) {
    const auto count = r.get<std::uint32_t>();
    if (count > kMaxTrackedPeriods) r.fail("corrupt period count");
    model.trackedPeriods.resize(count);
    for (ModelPeriod& period : model.trackedPeriods) {
      period.shift.x = r.get<double>(), period.shift.y = r.get<double>();
      period.score = r.get<double>();
    }
  }
  if (!r.atEnd()) r.fail("corrupt shape model file (unexpected data after the model)");
  if (model.levels.front().points.empty() || model.finePoints.empty())
    r.fail("corrupt shape model file (invalid values)");
  if (const std::string why = implausibility(model); !why.empty())
    r.fail("corrupt shape model file (invalid values: " + why + ")");
  if (version < 3) model.symmetries = findSearchSymmetries(model.levels);
  if (version < 4) model.trackedPeriods = findTrackedPeriods(model.levels);
  return model;
}

}  // namespace facet
