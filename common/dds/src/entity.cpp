#include "rigger/dds/entity.hpp"

#include <utility>

namespace rigger::dds {

DdsError::DdsError(const std::string& what, dds_return_t code)
    : std::runtime_error(what + " failed: " + dds_strretcode(code)), code_(code) {}

dds_return_t check(dds_return_t rc, const char* what) {
  if (rc < 0) throw DdsError(what, rc);
  return rc;
}

Entity::Entity(dds_entity_t handle, const char* what) : handle_(handle) {
  if (handle_ < 0) {
    const auto rc = handle_;
    handle_ = 0;
    throw DdsError(what, rc);
  }
}

Entity::Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}

Entity& Entity::operator=(Entity&& other) noexcept {
  if (this != &other) {
    if (handle_ > 0) dds_delete(handle_);
    handle_ = std::exchange(other.handle_, 0);
  }
  return *this;
}

Entity::~Entity() {
  if (handle_ > 0) dds_delete(handle_);
}

}  // namespace rigger::dds
