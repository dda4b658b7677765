#include "tests/sinks/test_certificates.hpp"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace facet::sinks_test {
namespace {

void run(const std::string& folder, const std::string& command) {
  const std::string log = folder + "/openssl.log";
  const std::string line = "cd '" + folder + "' && openssl " + command + " >>'" + log + "' 2>&1";
  if (std::system(line.c_str()) == 0) return;
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  throw std::runtime_error("openssl " + command + " failed:\n" + text.str());
}

constexpr const char* kNewKey = "-newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes";

// A self-signed authority <name>.pem / <name>.key.
void makeAuthority(const std::string& folder, const std::string& name) {
  run(folder, std::string("req -x509 ") + kNewKey + " -days 2 -subj /CN=" + name + " -keyout " +
                  name + ".key -out " + name + ".pem");
}

// <name>.pem / <name>.key signed by ca.pem, with the given subjectAltName (may be empty).
void makeSigned(const std::string& folder, const std::string& name, const std::string& commonName,
                const std::string& altName) {
  run(folder, std::string("req ") + kNewKey + " -subj /CN=" + commonName + " -keyout " + name +
                  ".key -out " + name + ".csr");
  std::string extensions;
  if (!altName.empty()) {
    std::ofstream(folder + "/" + name + ".ext") << "subjectAltName=" << altName << "\n";
    extensions = " -extfile " + name + ".ext";
  }
  run(folder, "x509 -req -in " + name + ".csr -CA ca.pem -CAkey ca.key -CAcreateserial -days 2" +
                  extensions + " -out " + name + ".pem");
}

}  // namespace

TestCertificates::TestCertificates(const std::string& folder) {
  if (::access("/usr/bin/openssl", X_OK) != 0)
    throw std::runtime_error(
        "/usr/bin/openssl is missing: install the Debian package openssl "
        "(deploy/install-deps.sh)");
  makeAuthority(folder, "ca");
  makeAuthority(folder, "foreign-ca");
  makeSigned(folder, "broker", "127.0.0.1", "IP:127.0.0.1");
  makeSigned(folder, "elsewhere", "elsewhere.example", "DNS:elsewhere.example");
  makeSigned(folder, "client", "facet-station", "");
  caFile = folder + "/ca.pem";
  brokerCertFile = folder + "/broker.pem";
  brokerKeyFile = folder + "/broker.key";
  elsewhereCertFile = folder + "/elsewhere.pem";
  elsewhereKeyFile = folder + "/elsewhere.key";
  clientCertFile = folder + "/client.pem";
  clientKeyFile = folder + "/client.key";
  foreignCaFile = folder + "/foreign-ca.pem";
}

}  // namespace facet::sinks_test
