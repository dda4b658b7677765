#include "camera/module_file.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <system_error>
#include <vector>

namespace facet {
namespace {
namespace fs = std::filesystem;

std::vector<fs::path> placesOf(const ModuleFile& module) {
  if (const char* file = std::getenv(module.environment); file && *file) return {file};
  std::vector<fs::path> paths;
  std::error_code ec;
  // The installed layout: <prefix>/bin/facet beside <prefix>/lib/facet/<module>.
  if (const fs::path exe = fs::read_symlink("/proc/self/exe", ec); !ec)
    paths.push_back((exe.parent_path() / module.fromBin / module.file).lexically_normal());
  paths.emplace_back(module.buildPath);
  return paths;
}

}  // namespace

void* openModule(const ModuleFile& module, const char* entry,
                 const std::function<std::string(void* symbol)>& accept, std::string& tried) {
  const auto note = [&](const std::string& why) { tried += (tried.empty() ? "" : "; ") + why; };
  for (const fs::path& path : placesOf(module)) {
    // RTLD_LOCAL: the module's own copies of shared code never replace the program's.
    void* handle = ::dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
    if (!handle) {
      const char* error = ::dlerror();
      const std::string why = error ? error : "cannot load";
      // dlerror() names the path itself for a missing file, a dependency for a broken one.
      note(why.starts_with(path.string()) ? why : path.string() + ": " + why);
      continue;
    }
    void* symbol = ::dlsym(handle, entry);
    const std::string refused = symbol ? accept(symbol) : std::string("no ") + entry;
    if (refused.empty()) return symbol;  // never closed: its code may run until the process ends
    note(path.string() + ": " + refused);
    ::dlclose(handle);
  }
  return nullptr;
}

}  // namespace facet
