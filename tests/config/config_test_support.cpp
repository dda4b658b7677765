#include "tests/config/config_test_support.hpp"

#include "service/engine/builtin_steps.hpp"

#include <atomic>
#include <fstream>

#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace facet::config::test {

const StepKindRegistry& facetSteps() {
  static const StepKindRegistry kinds = service::builtinSteps();
  return kinds;
}

ScratchFolder::ScratchFolder() {
  static std::atomic<int> counter{0};
  path_ = std::filesystem::temp_directory_path() /
          ("facet_config_test_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

ScratchFolder::~ScratchFolder() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::filesystem::path ScratchFolder::write(const std::string& name, const std::string& text) const {
  const auto file = path_ / name;
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary) << text;
  return file;
}

std::filesystem::path ScratchFolder::writeImage(const std::string& name, int width,
                                                int height) const {
  const auto file = path_ / name;
  std::filesystem::create_directories(file.parent_path());
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(40));
  cv::rectangle(image, {width / 4, height / 4}, {width / 2, 3 * height / 4}, cv::Scalar(200),
                cv::FILLED);
  cv::circle(image, {3 * width / 4, height / 2}, height / 6, cv::Scalar(220), cv::FILLED);
  cv::imwrite(file.string(), image);
  return file;
}

testing::AssertionResult hasDiagnostic(const Diagnostics& diagnostics, int line, int column,
                                       const std::string& fragment, bool warning) {
  const Severity wanted = warning ? Severity::Warning : Severity::Error;
  for (const auto& d : diagnostics.items())
    if (d.where.line == line && d.where.column == column && d.severity == wanted &&
        d.message.find(fragment) != std::string::npos)
      return testing::AssertionSuccess();
  return testing::AssertionFailure()
         << "no " << (warning ? "warning" : "error") << " at " << line << ":" << column
         << " containing \"" << fragment << "\"; got:\n"
         << diagnostics.text();
}

}  // namespace facet::config::test
