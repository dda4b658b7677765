#pragma once
// A module of this build: a CMake MODULE library that a program loads with dlopen when it first
// needs it (the image codecs, the GigE Vision camera), so that programs start without the heavy
// libraries behind it. Installed in lib/facet below the prefix; a program finds it beside its
// installed binary or in the build tree that built it.

#include <filesystem>
#include <functional>
#include <string>

namespace facet {

struct ModuleFile {
  const char* environment;  // variable naming the file; when set, the only place tried
  const char* file;         // the module's file name
  const char* fromBin;      // its folder relative to the installed binaries' folder
  const char* buildPath;    // where the build tree that built this program has it
};

// Opens the first place of `module` whose symbol `entry` `accept`s (it returns "" for yes, or
// why not) and returns that symbol; the module then stays loaded for the life of the process.
// nullptr when none does, with every path tried and its reason (dlerror()'s words) in `tried`.
void* openModule(const ModuleFile& module, const char* entry,
                 const std::function<std::string(void* symbol)>& accept, std::string& tried);

// The table of a module whose entry point `entry` is `const Table* entry()` and whose table
// carries the interface number `abi` this program was built for: a module from another build
// is passed over with the reason. nullptr when no place has one, as openModule.
template <typename Table>
const Table* openModuleTable(const ModuleFile& module, const char* entry, int abi,
                             std::string& tried) {
  const auto tableOf = [](void* symbol) { return reinterpret_cast<const Table* (*)()>(symbol)(); };
  const auto accept = [&](void* symbol) -> std::string {
    const Table* table = tableOf(symbol);
    if (!table) return std::string("no table from ") + entry;
    if (table->abi == abi) return {};
    return "built for interface " + std::to_string(table->abi) + ", this program needs " +
           std::to_string(abi);
  };
  void* symbol = openModule(module, entry, accept, tried);
  return symbol ? tableOf(symbol) : nullptr;
}

}  // namespace facet
