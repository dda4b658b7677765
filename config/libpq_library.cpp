#include "config/libpq_library.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace facet::config {
namespace {

constexpr const char* kSoname = "libpq.so.5";  // libpq's ABI, unchanged since PostgreSQL 8.0

struct Loaded {
  LibPq functions{};
  std::string problem;  // empty when loaded
};

Loaded load() {
  Loaded out;
  const char* chosen = std::getenv("FACET_LIBPQ");
  const std::string file = chosen && *chosen ? chosen : kSoname;
  // Never closed: connections may live until the process ends.
  void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* error = ::dlerror();
    out.problem = "PostgreSQL's client library cannot be loaded (install libpq5" +
                  std::string(chosen && *chosen ? ", or correct FACET_LIBPQ" : "") +
                  "): " + (error ? error : file);
    return out;
  }
  auto bind = [&](auto& function, const char* name) {
    function = reinterpret_cast<std::remove_reference_t<decltype(function)>>(::dlsym(handle, name));
    if (!function && out.problem.empty())
      out.problem = file + " has no " + name + " (not libpq, or too old a one)";
  };
  LibPq& f = out.functions;
  bind(f.connectdb, "PQconnectdb");
  bind(f.connectdbParams, "PQconnectdbParams");
  bind(f.status, "PQstatus");
  bind(f.errorMessage, "PQerrorMessage");
  bind(f.finish, "PQfinish");
  bind(f.exec, "PQexec");
  bind(f.execParams, "PQexecParams");
  bind(f.resultStatus, "PQresultStatus");
  bind(f.ntuples, "PQntuples");
  bind(f.getvalue, "PQgetvalue");
  bind(f.getisnull, "PQgetisnull");
  bind(f.cmdTuples, "PQcmdTuples");
  bind(f.clear, "PQclear");
  bind(f.conninfoParse, "PQconninfoParse");
  bind(f.conninfoFree, "PQconninfoFree");
  bind(f.freemem, "PQfreemem");
  return out;
}

}  // namespace

const LibPq& libpq() {
  static const Loaded loaded = load();
  if (!loaded.problem.empty()) throw std::runtime_error(loaded.problem);
  return loaded.functions;
}

}  // namespace facet::config
