#include "plc/register_bus.hpp"

#include <cerrno>

#include <modbus.h>

#include "plc/register_server.hpp"

namespace facet::plc {

bool ModbusException::deviceBusy() const {
  return code == EMBXSBUSY;
}

namespace {

// libmodbus reports a peer's exception as an errno at or above MODBUS_ENOBASE (EMBXILFUN ...);
// any other errno means the transport failed.
[[noreturn]] void raise(const std::string& what) {
  const int code = errno;
  const std::string message = what + ": " + modbus_strerror(code);
  if (code >= EMBXILFUN && code <= EMBXGTAR) throw ModbusException(code, message);
  throw LinkLost(message);
}

class ClientBus final : public RegisterBus {
 public:
  explicit ClientBus(PlcSettings settings) : settings_(std::move(settings)) {}
  ~ClientBus() override { close(); }

  void connect() override {
    close();
    ctx_ = settings_.transport == Transport::Rtu
               ? modbus_new_rtu(settings_.serialDevice.c_str(), settings_.baudRate,
                                settings_.parity, settings_.dataBits, settings_.stopBits)
               : modbus_new_tcp(settings_.host.c_str(), settings_.port);
    if (ctx_ == nullptr) throw LinkLost("cannot create a Modbus context for " + describe());
    const auto timeout = settings_.responseTimeout.count();
    modbus_set_response_timeout(ctx_, static_cast<std::uint32_t>(timeout / 1000),
                                static_cast<std::uint32_t>((timeout % 1000) * 1000));
    modbus_set_slave(ctx_, settings_.unitId);
    if (modbus_connect(ctx_) != 0) {
      const std::string reason = modbus_strerror(errno);
      close();
      throw LinkLost("cannot connect to " + describe() + ": " + reason);
    }
  }

  void close() override {
    if (ctx_ == nullptr) return;
    modbus_close(ctx_);
    modbus_free(ctx_);
    ctx_ = nullptr;
  }

  std::string describe() const override {
    const std::string unit = " unit " + std::to_string(settings_.unitId);
    if (settings_.transport == Transport::Rtu) return settings_.serialDevice + unit;
    return settings_.host + ":" + std::to_string(settings_.port) + unit;
  }

  void readCoils(int wire, int count, std::uint8_t* out) override {
    if (modbus_read_bits(live(), wire, count, out) != count) raise("reading coils");
  }
  void readRegisters(int wire, int count, std::uint16_t* out) override {
    if (modbus_read_registers(live(), wire, count, out) != count) raise("reading registers");
  }
  void writeCoil(int wire, bool value) override {
    if (modbus_write_bit(live(), wire, value ? 1 : 0) != 1) raise("writing a coil");
  }
  void writeCoils(int wire, int count, const std::uint8_t* values) override {
    if (modbus_write_bits(live(), wire, count, values) != count) raise("writing coils");
  }
  void writeRegisters(int wire, int count, const std::uint16_t* values) override {
    const int written = count == 1 ? modbus_write_register(live(), wire, values[0])
                                   : modbus_write_registers(live(), wire, count, values);
    if (written != count) raise("writing registers");
  }

 private:
  modbus_t* live() {
    if (ctx_ == nullptr) throw LinkLost("not connected to " + describe());
    return ctx_;
  }

  PlcSettings settings_;
  modbus_t* ctx_ = nullptr;
};

// The server's tables are finite: an address beyond them is what a PLC would answer with
// "illegal data address".
template <class F>
auto guard(F&& f) {
  try {
    return f();
  } catch (const std::out_of_range& e) {
    throw ModbusException(EMBXILADD, e.what());
  }
}

class ServerBus final : public RegisterBus {
 public:
  explicit ServerBus(RegisterServer& server) : server_(server) {}
  void connect() override {}
  void close() override {}
  std::string describe() const override {
    return "the daemon's Modbus server (port " + std::to_string(server_.port()) + ")";
  }
  void readCoils(int wire, int count, std::uint8_t* out) override {
    for (int i = 0; i < count; ++i) out[i] = guard([&] { return server_.coil(wire + i); });
  }
  void readRegisters(int wire, int count, std::uint16_t* out) override {
    guard([&] {
      server_.holdingRegisters(wire, count, out);
      return true;
    });
  }
  void writeCoil(int wire, bool value) override {
    guard([&] {
      server_.setCoil(wire, value);
      return true;
    });
  }
  void writeCoils(int wire, int count, const std::uint8_t* values) override {
    for (int i = 0; i < count; ++i)
      guard([&] {
        server_.setCoil(wire + i, values[i] != 0);
        return true;
      });
  }
  void writeRegisters(int wire, int count, const std::uint16_t* values) override {
    for (int i = 0; i < count; ++i)
      guard([&] {
        server_.setHoldingRegister(wire + i, values[i]);
        return true;
      });
  }

 private:
  RegisterServer& server_;
};

}  // namespace

std::unique_ptr<RegisterBus> makeClientBus(const PlcSettings& settings) {
  return std::make_unique<ClientBus>(settings);
}

std::unique_ptr<RegisterBus> makeServerBus(RegisterServer& server) {
  return std::make_unique<ServerBus>(server);
}

}  // namespace facet::plc
