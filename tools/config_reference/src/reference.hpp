#pragma once
/// @file
/// docs/config-reference.md: the configuration keys of every service that declares them in a settings
/// table (rigger/base/settings.hpp), one section per service.

#include <string>

namespace rigger::config_reference {

/// The whole page, as tools/update-config-reference writes it.
std::string reference_markdown();

}  // namespace rigger::config_reference
