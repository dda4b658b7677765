#pragma once
// libpq, PostgreSQL's client library, loaded on first use (dlopen of its soname) instead of linked.
// Linked, it and the TLS, Kerberos and LDAP libraries it brings (some 20) doubled the start-up of
// every `facet` command (bench_startup), while only a station with a PostgreSQL sink and
// `facet results export --postgres` use it. The functions keep libpq's own signatures
// (libpq-fe.h), so that the calls read as libpq's documentation writes them.

#include <libpq-fe.h>

namespace facet::config {

struct LibPq {
  decltype(&::PQconnectdb) connectdb;
  decltype(&::PQconnectdbParams) connectdbParams;
  decltype(&::PQstatus) status;
  decltype(&::PQerrorMessage) errorMessage;
  decltype(&::PQfinish) finish;
  decltype(&::PQexec) exec;
  decltype(&::PQexecParams) execParams;
  decltype(&::PQresultStatus) resultStatus;
  decltype(&::PQntuples) ntuples;
  decltype(&::PQgetvalue) getvalue;
  decltype(&::PQgetisnull) getisnull;
  decltype(&::PQcmdTuples) cmdTuples;
  decltype(&::PQclear) clear;
  decltype(&::PQconninfoParse) conninfoParse;
  decltype(&::PQconninfoFree) conninfoFree;
  decltype(&::PQfreemem) freemem;
};

// The library, loaded once per process (thread-safe): libpq.so.5, or the file the environment
// variable FACET_LIBPQ names (a site's own libpq build). Throws std::runtime_error naming the
// library and the loader's reason when it cannot be loaded (Debian's libpq5 is not installed).
const LibPq& libpq();

}  // namespace facet::config
