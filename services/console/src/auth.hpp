#pragma once
/// @file
/// Who may do what at the console: users with a role and the SHA-256 of their bearer token, read from
/// a users file that `console make-users` writes (tokens are printed once and never stored in clear).
///
///   {"users": [{"name": "ada", "role": "programmer", "token_sha256": "<64 hex>"}, ...]}
///
/// Roles are ordered: a viewer reads; an operator also answers prompts, pauses and stops; a programmer
/// also publishes recipes, cancels and resumes.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rigger::console {

enum class Role { kViewer = 0, kOperator = 1, kProgrammer = 2 };

const char* role_name(Role role);
std::optional<Role> parse_role(std::string_view text);

struct User {
  std::string name;
  Role role = Role::kViewer;
};

/// Lower-case hex SHA-256 of `text`.
std::string sha256_hex(std::string_view text);

/// `bytes` random bytes from the system's CSPRNG as lower-case hex. @throws std::runtime_error.
std::string random_hex(std::size_t bytes);

/// The users file in memory. Thread safety: const methods may be called from any thread.
class Users {
 public:
  Users() = default;
  /// Parses the users file's text (bounded); `source` names it in errors.
  /// @throws rigger::ConfigError naming the file and the JSON pointer of what is wrong.
  static Users parse(std::string_view text, const std::string& source);
  /// @throws rigger::ConfigError when the file is missing or wrong.
  static Users load(const std::string& path);

  /// The user whose token hashes to a known hash, compared in constant time per entry; nullopt else.
  std::optional<User> authenticate(std::string_view token) const;
  std::size_t size() const { return entries_.size(); }

 private:
  struct Entry {
    User user;
    std::string token_sha256;
  };
  std::vector<Entry> entries_;
};

/// One user to create: name and role.
struct NewUser {
  std::string name;
  Role role = Role::kViewer;
};

/// A created user with the token to hand to them (shown once).
struct CreatedUser {
  NewUser user;
  std::string token;
};

/// Creates a fresh token for each of `users`, writes the users file at `path` (mode 0600, folders
/// created) with their hashes, and returns the tokens. @throws std::runtime_error on I/O errors.
std::vector<CreatedUser> make_users(const std::string& path, const std::vector<NewUser>& users);

/// `console make-users --file PATH [--user NAME:ROLE]... [--url URL]`: prints one line per user with
/// its token and login link. Returns the process exit code.
int make_users_main(int argc, char** argv);

}  // namespace rigger::console
