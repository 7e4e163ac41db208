#include "rigger/base/install.hpp"

#include <system_error>

namespace rigger {

std::filesystem::path executable_path() {
  std::error_code ec;
  auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path{} : p;
}

std::filesystem::path data_dir(const std::filesystem::path& executable) {
  if (executable.empty()) return {};
  return executable.parent_path().parent_path() / "share" / "rigger";
}

}  // namespace rigger
