#include "rigger/compose/process_util.hpp"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rigger::compose {
namespace {

constexpr const char* kLockDir = "/tmp/rigger-compose";

std::string errno_text(int err) { return strerror(err); }

}  // namespace

void make_dirs(const std::string& path) {
  std::string partial;
  std::stringstream ss(path);
  std::string part;
  if (!path.empty() && path[0] == '/') partial = "/";
  while (std::getline(ss, part, '/')) {
    if (part.empty()) continue;
    partial += part + "/";
    if (mkdir(partial.c_str(), 0777) != 0 && errno != EEXIST)
      throw std::runtime_error("cannot create folder " + partial + ": " + errno_text(errno));
  }
}

DomainLock::DomainLock(std::uint32_t domain, std::string host) : domain_(domain), host_(std::move(host)) {}

DomainLock::~DomainLock() {
  if (fd_ >= 0) close(fd_);
}

std::string DomainLock::path(std::uint32_t domain, const std::string& host) {
  // Host names are [A-Za-z0-9.-] (compose_file checks them); anything else would not reach here.
  return std::string(kLockDir) + "/domain-" + std::to_string(domain) + (host.empty() ? "" : "@" + host) + ".lock";
}

bool DomainLock::try_lock(const std::string& log_dir) {
  make_dirs(kLockDir);
  const int fd = open(path(domain_, host_).c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0666);
  if (fd < 0) throw std::runtime_error("cannot open " + path(domain_, host_) + ": " + errno_text(errno));
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    close(fd);
    return false;
  }
  const std::string content = std::to_string(getpid()) + " " + log_dir + "\n";
  if (ftruncate(fd, 0) != 0 || pwrite(fd, content.data(), content.size(), 0) != static_cast<ssize_t>(content.size())) {
    close(fd);
    throw std::runtime_error("cannot write " + path(domain_, host_) + ": " + errno_text(errno));
  }
  fd_ = fd;
  return true;
}

std::optional<LockHolder> DomainLock::holder(std::uint32_t domain, const std::string& host) {
  const int fd = open(path(domain, host).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;  // never created: nobody holds it
  // A shared lock is granted only when nobody holds the exclusive one.
  if (flock(fd, LOCK_SH | LOCK_NB) == 0) {
    close(fd);
    return std::nullopt;
  }
  char buf[4096] = {};
  const ssize_t n = pread(fd, buf, sizeof buf - 1, 0);
  close(fd);
  LockHolder h;
  if (n > 0) {
    std::istringstream in(std::string(buf, static_cast<std::size_t>(n)));
    in >> h.pid;
    in.get();
    std::getline(in, h.log_dir);
  }
  return h;
}

std::string self_executable() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("cannot find this executable: " + errno_text(errno));
  return std::string(buf, static_cast<std::size_t>(n));
}

std::vector<std::string> this_host_names(const std::string& configured) {
  std::vector<std::string> out;
  if (!configured.empty()) out.push_back(configured);
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) == 0 && buf[0]) {
    const std::string full(buf);
    out.push_back(full);
    const auto dot = full.find('.');
    if (dot != std::string::npos) out.push_back(full.substr(0, dot));
  }
  return out;
}

std::optional<std::string> read_text_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace rigger::compose
