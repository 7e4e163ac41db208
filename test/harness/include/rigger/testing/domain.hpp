#pragma once
/// @file
/// Every DDS test runs on a domain id of its own so that tests run in parallel without crosstalk.

#include <cstdint>
#include <string>

namespace rigger::testing {

/// Holds one DDS domain id exclusively (an flock'ed file under /tmp/rigger-test-domains) for its
/// lifetime, across all processes on the machine. Also points CYCLONEDDS_URI at deploy/cyclonedds.xml
/// (unless already set) so the test and its children use rigger's loopback configuration.
class DomainLease {
 public:
  /// @throws std::runtime_error when every id in [first, last] is taken.
  explicit DomainLease(std::uint32_t first = 20, std::uint32_t last = 230);
  DomainLease(const DomainLease&) = delete;
  DomainLease& operator=(const DomainLease&) = delete;
  ~DomainLease();
  std::uint32_t id() const { return id_; }

 private:
  std::uint32_t id_ = 0;
  int fd_ = -1;
};

/// file:// URI of the repository's deploy/cyclonedds.xml.
std::string default_dds_config_uri();
/// Directory holding the built service binaries ($RIGGER_BIN_DIR, else <build>/bin).
std::string bin_dir();

}  // namespace rigger::testing
