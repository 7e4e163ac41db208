#include "rigger/testing/domain.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace rigger::testing {

std::string default_dds_config_uri() { return std::string("file://") + RIGGER_SOURCE_DIR + "/deploy/cyclonedds.xml"; }

std::string bin_dir() {
  const char* env = std::getenv("RIGGER_BIN_DIR");
  return env && *env ? env : std::string(RIGGER_BINARY_DIR) + "/bin";
}

DomainLease::DomainLease(std::uint32_t first, std::uint32_t last) {
  setenv("CYCLONEDDS_URI", default_dds_config_uri().c_str(), 0);
  const std::string dir = "/tmp/rigger-test-domains";
  mkdir(dir.c_str(), 0777);
  const std::uint32_t span = last - first + 1;
  // Start at a pid-dependent offset so that parallel tests rarely contend for the same lock file.
  const std::uint32_t offset = static_cast<std::uint32_t>(getpid()) % span;
  for (std::uint32_t i = 0; i < span; ++i) {
    const std::uint32_t id = first + (offset + i) % span;
    const std::string path = dir + "/" + std::to_string(id) + ".lock";
    const int fd = open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (flock(fd, LOCK_EX | LOCK_NB) == 0) {
      id_ = id;
      fd_ = fd;
      return;
    }
    close(fd);
  }
  throw std::runtime_error("no free DDS domain id in [" + std::to_string(first) + ", " + std::to_string(last) + "]");
}

DomainLease::~DomainLease() {
  if (fd_ >= 0) close(fd_);  // releases the flock
}

}  // namespace rigger::testing
