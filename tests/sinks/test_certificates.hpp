#pragma once
// TestCertificates: a throw-away certificate authority made with Debian's `openssl` command in
// the test's folder, a broker certificate it signs for 127.0.0.1, a client certificate it signs,
// and a second, unrelated authority (a station configured with the wrong CA file). Elliptic-curve
// keys: made in milliseconds.

#include <string>

namespace facet::sinks_test {

struct TestCertificates {
  // Makes every file below in `folder`; throws with openssl's output when a step fails.
  explicit TestCertificates(const std::string& folder);

  std::string caFile;          // the authority that signed the broker's and the client's
  std::string brokerCertFile;  // CN and subjectAltName IP 127.0.0.1
  std::string brokerKeyFile;
  std::string elsewhereCertFile;  // signed by the CA for another host (elsewhere.example)
  std::string elsewhereKeyFile;
  std::string clientCertFile;  // CN facet-station
  std::string clientKeyFile;
  std::string foreignCaFile;  // signed nothing here
};

}  // namespace facet::sinks_test
