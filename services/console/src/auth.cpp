#include "auth.hpp"

#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <openssl/evp.h>
#include <openssl/rand.h>

#include "rigger/base/config.hpp"
#include "rigger/base/bounded_json.hpp"

namespace rigger::console {

namespace {

std::string to_hex(const unsigned char* data, std::size_t n) {
  static const char* kDigits = "0123456789abcdef";
  std::string out;
  out.reserve(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    out += kDigits[data[i] >> 4];
    out += kDigits[data[i] & 0xf];
  }
  return out;
}

// Compares without an early exit, so the time taken does not tell how many leading characters match.
bool equal_constant_time(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

bool is_hex64(const std::string& s) {
  if (s.size() != 64) return false;
  for (char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

}  // namespace

const char* role_name(Role role) {
  switch (role) {
    case Role::kViewer: return "viewer";
    case Role::kOperator: return "operator";
    case Role::kProgrammer: return "programmer";
  }
  return "?";
}

std::optional<Role> parse_role(std::string_view text) {
  if (text == "viewer") return Role::kViewer;
  if (text == "operator") return Role::kOperator;
  if (text == "programmer") return Role::kProgrammer;
  return std::nullopt;
}

std::string sha256_hex(std::string_view text) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  EVP_Digest(text.data(), text.size(), digest, &n, EVP_sha256(), nullptr);
  return to_hex(digest, n);
}

std::string random_hex(std::size_t bytes) {
  std::vector<unsigned char> buf(bytes);
  if (RAND_bytes(buf.data(), static_cast<int>(buf.size())) != 1) throw std::runtime_error("no random bytes");
  return to_hex(buf.data(), buf.size());
}

Users Users::parse(std::string_view text, const std::string& source) {
  rigger::JsonLimits limits;
  limits.max_bytes = 1024U * 1024U;
  limits.max_depth = 8;
  const auto parsed = rigger::parse_json_bounded(text, limits);
  if (!parsed.ok()) throw ConfigError(source, parsed.error->pointer, parsed.error->to_string());
  const auto& doc = parsed.value;
  if (!doc.is_object() || !doc.contains("users") || !doc["users"].is_array())
    throw ConfigError(source, "/users", "expected an object with a \"users\" array");
  Users users;
  for (std::size_t i = 0; i < doc["users"].size(); ++i) {
    const auto& u = doc["users"][i];
    const std::string at = "/users/" + std::to_string(i);
    if (!u.is_object()) throw ConfigError(source, at, "expected an object");
    for (const char* key : {"name", "role", "token_sha256"})
      if (!u.contains(key) || !u[key].is_string())
        throw ConfigError(source, at + "/" + key, std::string("expected a string \"") + key + "\"");
    Entry e;
    e.user.name = u["name"].get<std::string>();
    const auto role = parse_role(u["role"].get<std::string>());
    if (!role) throw ConfigError(source, at + "/role", "expected viewer, operator or programmer");
    e.user.role = *role;
    e.token_sha256 = u["token_sha256"].get<std::string>();
    if (!is_hex64(e.token_sha256))
      throw ConfigError(source, at + "/token_sha256", "expected 64 lower-case hex digits (a SHA-256)");
    if (e.user.name.empty()) throw ConfigError(source, at + "/name", "expected a non-empty name");
    users.entries_.push_back(std::move(e));
  }
  return users;
}

Users Users::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path, "", "cannot read the users file (create it with: console make-users --file " + path + ")");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse(text, path);
}

std::optional<User> Users::authenticate(std::string_view token) const {
  if (token.empty() || token.size() > 256) return std::nullopt;
  const std::string hash = sha256_hex(token);
  std::optional<User> found;
  for (const auto& e : entries_)
    if (equal_constant_time(hash, e.token_sha256) && !found) found = e.user;
  return found;
}

std::vector<CreatedUser> make_users(const std::string& path, const std::vector<NewUser>& users) {
  std::vector<CreatedUser> created;
  nlohmann::json doc = {{"users", nlohmann::json::array()}};
  for (const auto& u : users) {
    CreatedUser c{u, random_hex(24)};
    doc["users"].push_back({{"name", u.name}, {"role", role_name(u.role)}, {"token_sha256", sha256_hex(c.token)}});
    created.push_back(std::move(c));
  }
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + tmp);
    ::chmod(tmp.c_str(), 0600);
    out << doc.dump(2) << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  std::filesystem::rename(tmp, p);
  return created;
}

int make_users_main(int argc, char** argv) {
  std::string file, url;
  std::vector<NewUser> users;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--file" && has_value) {
      file = argv[++i];
    } else if (arg == "--url" && has_value) {
      url = argv[++i];
    } else if (arg == "--user" && has_value) {
      const std::string spec = argv[++i];
      const auto colon = spec.find(':');
      const auto role = colon == std::string::npos ? std::nullopt : parse_role(spec.substr(colon + 1));
      if (!role || colon == 0) {
        std::fprintf(stderr, "console make-users: --user %s: expected NAME:ROLE with ROLE viewer, operator or programmer\n",
                     spec.c_str());
        return 2;
      }
      users.push_back({spec.substr(0, colon), *role});
    } else {
      std::fprintf(stderr,
                   "usage: console make-users --file PATH [--user NAME:ROLE]... [--url http://HOST:PORT]\n"
                   "  writes PATH (tokens hashed) and prints each user's token and login link once\n");
      return 2;
    }
  }
  if (file.empty()) {
    std::fprintf(stderr, "console make-users: --file PATH is required\n");
    return 2;
  }
  if (users.empty())
    users = {{"programmer", Role::kProgrammer}, {"operator", Role::kOperator}, {"viewer", Role::kViewer}};
  try {
    for (const auto& c : make_users(file, users)) {
      std::printf("%s %s %s", c.user.name.c_str(), role_name(c.user.role), c.token.c_str());
      if (!url.empty()) std::printf(" %s/?token=%s", url.c_str(), c.token.c_str());
      std::printf("\n");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "console make-users: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace rigger::console
