#pragma once
/// @file
/// The project's one content digest: the lower-case hex SHA-256 of bytes (OpenSSL). STEP models, cell
/// documents and recipes are named by it.

#include <string>
#include <string_view>

namespace rigger {

/// Hex sha256 (64 lower-case digits) of `bytes`.
std::string sha256_hex(std::string_view bytes);

/// Whether `text` looks like what sha256_hex returns: 64 lower-case hex digits.
bool is_sha256_hex(std::string_view text);

}  // namespace rigger
