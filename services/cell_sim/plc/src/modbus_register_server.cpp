#include "rigger/plc/modbus_register_server.hpp"

#include <arpa/inet.h>
#include <modbus/modbus-tcp.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

namespace rigger::plc {
namespace {

constexpr std::uint8_t kWriteSingleRegister = 0x06;
constexpr std::uint8_t kWriteMultipleRegisters = 0x10;
constexpr std::uint8_t kMaskWriteRegister = 0x16;
constexpr std::uint8_t kWriteAndReadRegisters = 0x17;

std::uint16_t be16(const std::uint8_t* bytes) {
  return static_cast<std::uint16_t>((bytes[0] << 8U) | bytes[1]);
}

}  // namespace

ModbusRegisterServer::ModbusRegisterServer(ModbusServerConfig config, std::uint16_t register_count,
                                           std::uint16_t writable_begin,
                                           std::uint16_t writable_count)
    : config_(std::move(config)),
      register_count_(register_count),
      writable_begin_(writable_begin),
      writable_count_(writable_count) {
  if (register_count_ == 0 || writable_begin_ + writable_count_ > register_count_) {
    throw crane::ModbusError("modbus server: the writable range must lie inside the registers");
  }
  if (config_.max_clients < 1 || config_.byte_timeout <= std::chrono::milliseconds::zero()) {
    throw crane::ModbusError("modbus server: max_clients and byte_timeout must be positive");
  }
  mapping_ = modbus_mapping_new_start_address(0, 0, 0, 0, 0, register_count_, 0, 0);
  if (mapping_ == nullptr) {
    throw crane::ModbusError("modbus server: cannot allocate the register mapping: " +
                             crane::modbus_error_text(errno));
  }
}

ModbusRegisterServer::~ModbusRegisterServer() {
  stop();
  modbus_mapping_free(mapping_);
}

void ModbusRegisterServer::start() {
  const std::lock_guard<std::mutex> lock(lifecycle_mutex_);
  if (thread_.joinable()) {
    return;
  }
  const std::string where = config_.address + ":" + std::to_string(config_.port);
  // libmodbus takes any string and binds to inet_addr()'s result, which is 255.255.255.255 for
  // garbage: check the address first.
  in_addr parsed{};
  if (inet_pton(AF_INET, config_.address.c_str(), &parsed) != 1) {
    throw crane::ModbusError("modbus server " + where + ": bad address (IPv4 expected)");
  }
  crane::ModbusContextPtr context(modbus_new_tcp(config_.address.c_str(), config_.port));
  if (!context) {
    throw crane::ModbusError("modbus server " + where + ": " + crane::modbus_error_text(errno));
  }
  const auto ms = config_.byte_timeout.count();
  modbus_set_byte_timeout(context.get(), static_cast<std::uint32_t>(ms / 1000),
                          static_cast<std::uint32_t>((ms % 1000) * 1000));
  const int listen_fd = modbus_tcp_listen(context.get(), config_.max_clients);
  if (listen_fd < 0) {
    throw crane::ModbusError("modbus server " + where +
                             ": cannot listen: " + crane::modbus_error_text(errno));
  }
  sockaddr_in bound{};
  socklen_t length = sizeof bound;
  if (getsockname(listen_fd, reinterpret_cast<sockaddr*>(&bound), &length) != 0) {
    const int error = errno;
    close(listen_fd);
    throw crane::ModbusError("modbus server " + where + ": getsockname: " + std::strerror(error));
  }
  wake_fd_ = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) {
    const int error = errno;
    close(listen_fd);
    throw crane::ModbusError("modbus server " + where + ": eventfd: " + std::strerror(error));
  }
  context_ = std::move(context);
  bound_port_ = ntohs(bound.sin_port);
  running_ = true;
  thread_ = std::thread([this, listen_fd] { serve(listen_fd); });
}

void ModbusRegisterServer::stop() {
  const std::lock_guard<std::mutex> lock(lifecycle_mutex_);
  if (!thread_.joinable()) {
    return;
  }
  const std::uint64_t one = 1;
  // An eventfd write of 8 bytes cannot be partial; it fails only if the counter would overflow.
  [[maybe_unused]] const auto written = write(wake_fd_, &one, sizeof one);
  thread_.join();
  close(wake_fd_);
  wake_fd_ = -1;
  // The sockets were closed by the server thread; keep modbus_close() off them.
  modbus_set_socket(context_.get(), -1);
  context_.reset();
  bound_port_ = 0;
  running_ = false;
  const std::lock_guard<std::mutex> stats_lock(stats_mutex_);
  stats_.clients = 0;
}

void ModbusRegisterServer::with_registers(
    const std::function<void(std::uint16_t* registers, std::size_t count)>& fn) {
  const std::lock_guard<std::mutex> lock(registers_mutex_);
  fn(mapping_->tab_registers, register_count_);
}

ModbusServerStats ModbusRegisterServer::stats() const {
  const std::lock_guard<std::mutex> lock(stats_mutex_);
  return stats_;
}

void ModbusRegisterServer::set_on_request(std::function<void()> on_request) {
  const std::lock_guard<std::mutex> lock(stats_mutex_);
  on_request_ = std::move(on_request);
}

bool ModbusRegisterServer::writes_outside(const std::uint8_t* query, int length) const {
  const int offset = modbus_get_header_length(context_.get());
  if (length < offset + 1) {
    return false;
  }
  const std::uint8_t* pdu = query + offset;
  const int pdu_length = length - offset;
  std::uint32_t address = 0;
  std::uint32_t count = 0;
  switch (pdu[0]) {
    case kWriteSingleRegister:
    case kMaskWriteRegister:
      if (pdu_length < 3) return false;
      address = be16(pdu + 1);
      count = 1;
      break;
    case kWriteMultipleRegisters:
      if (pdu_length < 5) return false;
      address = be16(pdu + 1);
      count = be16(pdu + 3);
      break;
    case kWriteAndReadRegisters:
      if (pdu_length < 9) return false;
      address = be16(pdu + 5);
      count = be16(pdu + 7);
      break;
    default:
      return false;  // reads, and functions the mapping does not serve (libmodbus answers those)
  }
  return address < writable_begin_ || address + count > writable_begin_ + writable_count_;
}

void ModbusRegisterServer::close_clients(std::vector<int>& clients) {
  for (const int fd : clients) {
    close(fd);
  }
  clients.clear();
}

void ModbusRegisterServer::serve(int listen_fd) {
  std::vector<int> clients;
  std::vector<pollfd> fds;
  std::array<std::uint8_t, MODBUS_TCP_MAX_ADU_LENGTH> query{};
  modbus_t* const context = context_.get();

  const auto update_clients = [&] {
    const std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.clients = static_cast<int>(clients.size());
  };

  for (;;) {
    fds.clear();
    fds.push_back({wake_fd_, POLLIN, 0});
    fds.push_back({listen_fd, POLLIN, 0});
    for (const int fd : clients) {
      fds.push_back({fd, POLLIN, 0});
    }
    if (poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (fds[0].revents != 0) {
      break;
    }
    if ((fds[1].revents & POLLIN) != 0) {
      const int fd = accept4(listen_fd, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd >= 0) {
        const std::lock_guard<std::mutex> lock(stats_mutex_);
        if (static_cast<int>(clients.size()) >= config_.max_clients) {
          close(fd);
          ++stats_.connections_refused;
        } else {
          const int one = 1;
          setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
          clients.push_back(fd);
          ++stats_.connections_accepted;
          stats_.clients = static_cast<int>(clients.size());
        }
      }
    }
    std::vector<int> dropped;
    for (std::size_t i = 2; i < fds.size(); ++i) {
      if (fds[i].revents == 0) continue;
      const int fd = fds[i].fd;
      modbus_set_socket(context, fd);
      const int length = modbus_receive(context, query.data());
      if (length == 0) {
        continue;  // addressed to another unit (serial gateways only)
      }
      if (length < 0) {
        dropped.push_back(fd);  // closed by the peer, or a malformed frame: drop the client
        continue;
      }
      const bool rejected = writes_outside(query.data(), length);
      // Counted before the reply goes out: a client that has its answer also sees it in stats().
      std::function<void()> on_request;
      {
        const std::lock_guard<std::mutex> lock(stats_mutex_);
        ++(rejected ? stats_.requests_rejected : stats_.requests_served);
        on_request = on_request_;
      }
      int reply = 0;
      {
        const std::lock_guard<std::mutex> lock(registers_mutex_);
        reply = rejected ? modbus_reply_exception(context, query.data(),
                                                  MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS)
                         : modbus_reply(context, query.data(), length, mapping_);
      }
      if (reply < 0) {
        dropped.push_back(fd);
      }
      if (on_request) {
        on_request();
      }
    }
    for (const int fd : dropped) {
      close(fd);
      clients.erase(std::find(clients.begin(), clients.end(), fd));
    }
    if (!dropped.empty()) {
      update_clients();
    }
  }
  close_clients(clients);
  close(listen_fd);
  update_clients();
}

}  // namespace rigger::plc
