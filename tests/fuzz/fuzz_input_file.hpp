#pragma once
// Fuzz targets whose entry point takes a file name: each input is written to a file in a folder
// of this process (in /dev/shm when there is one, so that the disk is not worn out by millions
// of writes). The folder is removed when the process exits normally.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace facet::fuzz {

class FuzzInputFolder {
 public:
  FuzzInputFolder() {
    const std::filesystem::path shm = "/dev/shm";
    const auto parent =
        std::filesystem::is_directory(shm) ? shm : std::filesystem::temp_directory_path();
    folder_ = parent / ("facet-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
  }
  ~FuzzInputFolder() {
    std::error_code ec;
    std::filesystem::remove_all(folder_, ec);
  }
  FuzzInputFolder(const FuzzInputFolder&) = delete;
  FuzzInputFolder& operator=(const FuzzInputFolder&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return folder_; }

  // Writes `size` bytes to `name` inside the folder (replacing it) and returns its path.
  std::filesystem::path write(const std::string& name, const std::uint8_t* data,
                              std::size_t size) const {
    const auto file = folder_ / name;
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return file;
  }

 private:
  std::filesystem::path folder_;
};

}  // namespace facet::fuzz
