#include "plc/register_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include <modbus.h>

namespace facet::plc {

struct RegisterServer::State {
  RegisterServerOptions options;
  modbus_t* ctx = nullptr;
  modbus_mapping_t* mapping = nullptr;
  int listenSocket = -1;
  int boundPort = 0;
  std::vector<int> clients;
  mutable std::mutex mutex;  // guards mapping
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> served{0};
  std::atomic<int> connected{0};
  std::thread thread;

  void serve();
  void acceptClient();
  bool answer(int socket);  // false: the client is gone
};

void RegisterServer::State::acceptClient() {
  const int socket = ::accept(listenSocket, nullptr, nullptr);
  if (socket < 0) return;
  if (static_cast<int>(clients.size()) >= options.maxClients) {
    ::close(socket);
    return;
  }
  clients.push_back(socket);
  connected = static_cast<int>(clients.size());
}

bool RegisterServer::State::answer(int socket) {
  std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  modbus_set_socket(ctx, socket);
  const int length = modbus_receive(ctx, query);
  if (length < 0) return false;
  if (length == 0) return true;  // not for us
  std::lock_guard lock(mutex);
  if (modbus_reply(ctx, query, length, mapping) < 0) return false;
  ++served;
  return true;
}

void RegisterServer::State::serve() {
  while (!stopping) {
    fd_set readable;
    FD_ZERO(&readable);
    FD_SET(listenSocket, &readable);
    int highest = listenSocket;
    for (int c : clients) {
      FD_SET(c, &readable);
      highest = std::max(highest, c);
    }
    // A short timeout bounds how long the destructor waits for this thread.
    timeval timeout{0, 20000};
    const int ready = ::select(highest + 1, &readable, nullptr, nullptr, &timeout);
    if (ready < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (ready == 0) continue;
    if (FD_ISSET(listenSocket, &readable)) acceptClient();
    for (auto it = clients.begin(); it != clients.end();) {
      if (FD_ISSET(*it, &readable) && !answer(*it)) {
        ::close(*it);
        it = clients.erase(it);
        connected = static_cast<int>(clients.size());
      } else {
        ++it;
      }
    }
  }
}

RegisterServer::RegisterServer(RegisterServerOptions options) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.options = std::move(options);
  const std::string where = s.options.host + ":" + std::to_string(s.options.port);
  s.ctx = modbus_new_tcp(s.options.host.c_str(), s.options.port);
  if (s.ctx == nullptr) throw std::runtime_error("cannot create a Modbus server on " + where);
  s.mapping = modbus_mapping_new(s.options.coils, 0, s.options.holdingRegisters, 0);
  if (s.mapping == nullptr) {
    modbus_free(s.ctx);
    throw std::runtime_error("cannot allocate the Modbus register tables");
  }
  s.listenSocket = modbus_tcp_listen(s.ctx, 8);
  if (s.listenSocket < 0) {
    const std::string reason = modbus_strerror(errno);
    modbus_mapping_free(s.mapping);
    modbus_free(s.ctx);
    throw std::runtime_error("cannot listen for Modbus TCP on " + where + ": " + reason);
  }
  sockaddr_in address{};
  socklen_t length = sizeof(address);
  ::getsockname(s.listenSocket, reinterpret_cast<sockaddr*>(&address), &length);
  s.boundPort = ntohs(address.sin_port);
  s.thread = std::thread([&s] { s.serve(); });
}

RegisterServer::~RegisterServer() {
  State& s = *state_;
  s.stopping = true;
  if (s.thread.joinable()) s.thread.join();
  for (int c : s.clients) ::close(c);
  ::close(s.listenSocket);
  modbus_mapping_free(s.mapping);
  modbus_free(s.ctx);
}

int RegisterServer::port() const {
  return state_->boundPort;
}

namespace {
void checkRange(int address, int count, int size, const char* table) {
  if (address < 0 || count < 0 || address + count > size)
    throw std::out_of_range(std::string(table) + " " + std::to_string(address) +
                            " is outside the server's 0.." + std::to_string(size - 1));
}
}  // namespace

bool RegisterServer::coil(int address) const {
  std::lock_guard lock(state_->mutex);
  checkRange(address, 1, state_->mapping->nb_bits, "coil");
  return state_->mapping->tab_bits[address] != 0;
}

void RegisterServer::setCoil(int address, bool value) {
  std::lock_guard lock(state_->mutex);
  checkRange(address, 1, state_->mapping->nb_bits, "coil");
  state_->mapping->tab_bits[address] = value ? 1 : 0;
}

std::uint16_t RegisterServer::holdingRegister(int address) const {
  std::lock_guard lock(state_->mutex);
  checkRange(address, 1, state_->mapping->nb_registers, "holding register");
  return state_->mapping->tab_registers[address];
}

void RegisterServer::setHoldingRegister(int address, std::uint16_t value) {
  std::lock_guard lock(state_->mutex);
  checkRange(address, 1, state_->mapping->nb_registers, "holding register");
  state_->mapping->tab_registers[address] = value;
}

void RegisterServer::holdingRegisters(int address, int count, std::uint16_t* out) const {
  std::lock_guard lock(state_->mutex);
  checkRange(address, count, state_->mapping->nb_registers, "holding register");
  std::memcpy(out, state_->mapping->tab_registers + address, sizeof(std::uint16_t) * count);
}

std::uint64_t RegisterServer::requestsServed() const {
  return state_->served;
}
int RegisterServer::clientsConnected() const {
  return state_->connected;
}

}  // namespace facet::plc
