#pragma once
// RegisterServer: a Modbus TCP server (libmodbus) serving coils and holding registers from its
// own thread. The PLC simulator uses it as "the PLC"; PlcLink's server role uses it so that the
// PLC can poll the daemon. Local code reads and writes the same tables under a lock.

#include <cstdint>
#include <memory>
#include <string>

namespace facet::plc {

struct RegisterServerOptions {
  std::string host = "127.0.0.1";  // address to listen on
  int port = 0;                    // 0: pick a free port (see RegisterServer::port())
  int coils = 4096;                // coils 0 .. coils-1 (wire addresses)
  int holdingRegisters = 4096;     // holding registers 0 .. holdingRegisters-1
  int maxClients = 8;              // simultaneous connections; more are refused
};

class RegisterServer {
 public:
  // Binds and starts serving. Throws std::runtime_error naming host:port when it cannot bind.
  explicit RegisterServer(RegisterServerOptions options);
  ~RegisterServer();  // stops serving and closes every connection
  RegisterServer(const RegisterServer&) = delete;
  RegisterServer& operator=(const RegisterServer&) = delete;

  int port() const;  // the port actually bound

  // Local access by wire address. Out-of-range addresses throw std::out_of_range.
  bool coil(int address) const;
  void setCoil(int address, bool value);
  std::uint16_t holdingRegister(int address) const;
  void setHoldingRegister(int address, std::uint16_t value);
  // Copies `count` registers starting at `address` into `out` under one lock (a consistent view).
  void holdingRegisters(int address, int count, std::uint16_t* out) const;

  // Requests served so far (all clients), and clients connected now.
  std::uint64_t requestsServed() const;
  int clientsConnected() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace facet::plc
