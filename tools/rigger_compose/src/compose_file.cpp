#include "rigger/compose/compose_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "rigger/compose/start_order.hpp"

namespace rigger::compose {
namespace fs = std::filesystem;
namespace {

constexpr std::uint32_t kMaxDomain = 232;
constexpr double kMaxTimeoutS = 3600;
constexpr std::size_t kMaxNameLength = 64;
const std::vector<std::string> kTopKeys{"root", "bin_dir", "log_dir", "dds", "services"};
const std::vector<std::string> kDdsKeys{"domain", "config"};
const std::vector<std::string> kServiceKeys{"binary",  "args",       "config",          "host",
                                            "restart", "depends_on", "ready_timeout_s", "stop_timeout_s",
                                            "env",     "description"};

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

int line_of(const YAML::Node& node) { return node.IsDefined() && node.Mark().line >= 0 ? node.Mark().line + 1 : 0; }

std::string kind_of(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Null: return "nothing (null)";
    case YAML::NodeType::Scalar: return "'" + node.Scalar() + "'";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a mapping";
    case YAML::NodeType::Undefined: return "nothing";
  }
  return "?";
}

bool valid_service_name(const std::string& name) {
  if (name.empty() || name.size() > kMaxNameLength) return false;
  if (!std::isalnum(static_cast<unsigned char>(name[0]))) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

bool valid_env_name(const std::string& name) {
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

class Parser {
 public:
  Parser(std::string file, const ParseOptions& options) : file_(std::move(file)), options_(options) {}

  ComposeFile parse(const std::string& text) {
    YAML::Node root;
    try {
      root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
      throw ComposeError(file_, e.mark.line >= 0 ? e.mark.line + 1 : 0, "", "not valid YAML: " + e.msg);
    }
    if (!root.IsMap()) fail(root, "", "expected a mapping with a 'services:' key, got " + kind_of(root));
    check_keys(root, "", kTopKeys);

    ComposeFile out;
    out.path = file_;
    const fs::path file_dir = fs::path(file_).parent_path();
    out.root = resolve(file_dir, root["root"] ? string_at(root["root"], "root") : std::string(".."));

    const YAML::Node dds = root["dds"];
    if (dds) {
      if (!dds.IsMap()) fail(dds, "dds", "expected a mapping with 'domain' and 'config', got " + kind_of(dds));
      check_keys(dds, "dds.", kDdsKeys);
      if (dds["domain"]) out.domain = domain_at(dds["domain"], "dds.domain");
      if (dds["config"]) out.dds_config = resolve(out.root, string_at(dds["config"], "dds.config"));
    }
    if (options_.domain) out.domain = *options_.domain;
    if (out.domain > kMaxDomain)
      fail(YAML::Node(), "dds.domain", "domain " + std::to_string(out.domain) + " is not in [0, 232]");

    if (root["bin_dir"]) out.bin_dir = resolve(out.root, string_at(root["bin_dir"], "bin_dir"));
    else out.bin_dir = options_.default_bin_dir.empty() ? resolve(out.root, "build/bin") : options_.default_bin_dir;
    out.log_dir = root["log_dir"] ? resolve(out.root, string_at(root["log_dir"], "log_dir"))
                                  : "/tmp/rigger-compose/" + std::to_string(out.domain);

    const YAML::Node services = root["services"];
    if (!services) fail(root, "services", "missing: the file must list its services under 'services:'");
    if (!services.IsMap())
      fail(services, "services", "expected a mapping of service name to service, got " + kind_of(services));
    if (services.size() == 0)
      fail(services, "services", "expected a mapping of service name to service, got an empty one");
    std::map<std::string, int> seen;
    for (auto it = services.begin(); it != services.end(); ++it) {
      const std::string name = it->first.IsScalar() ? it->first.Scalar() : "";
      const auto [prev, inserted] = seen.emplace(name, line_of(it->first));
      if (!inserted)
        fail(it->first, "services." + name,
             "service defined twice (first on line " + std::to_string(prev->second) + ")");
      out.services.push_back(service(it->first, it->second, out));
    }
    check_dependencies(services, out);
    return out;
  }

 private:
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key_path, const std::string& problem) const {
    throw ComposeError(file_, line_of(at), key_path, problem);
  }

  // Unknown keys are errors (a typo like 'restrat' must not be silently ignored), and so are duplicates.
  void check_keys(const YAML::Node& map, const std::string& prefix, const std::vector<std::string>& allowed) const {
    std::map<std::string, int> seen;
    for (auto it = map.begin(); it != map.end(); ++it) {
      if (!it->first.IsScalar()) fail(it->first, prefix, "keys must be plain names, got " + kind_of(it->first));
      const std::string key = it->first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        fail(it->first, prefix + key, "unknown key '" + key + "' (expected one of: " + join(allowed) + ")");
      const auto [prev, inserted] = seen.emplace(key, line_of(it->first));
      if (!inserted)
        fail(it->first, prefix + key, "key given twice (first on line " + std::to_string(prev->second) + ")");
    }
  }

  std::string string_at(const YAML::Node& node, const std::string& key_path) const {
    if (!node.IsScalar()) fail(node, key_path, "expected a string, got " + kind_of(node));
    try {
      return expand_variables(node.Scalar(), options_.env);
    } catch (const std::invalid_argument& e) {
      fail(node, key_path, e.what());
    }
  }

  double number_at(const YAML::Node& node, const std::string& key_path, double lo, double hi, bool lo_open) const {
    const std::string text = string_at(node, key_path);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    const std::string range = std::string(lo_open ? "(" : "[") + trim_number(lo) + ", " + trim_number(hi) + "]";
    if (text.empty() || *end != '\0' || !std::isfinite(v))
      fail(node, key_path, "expected a number in " + range + ", got '" + text + "'");
    if (v > hi || v < lo || (lo_open && v == lo))
      fail(node, key_path, "expected a number in " + range + ", got " + text);
    return v;
  }

  static std::string trim_number(double v) {
    std::ostringstream ss;
    ss << v;
    return ss.str();
  }

  std::uint32_t domain_at(const YAML::Node& node, const std::string& key_path) const {
    const double v = number_at(node, key_path, 0, kMaxDomain, false);
    if (v != std::floor(v)) fail(node, key_path, "expected an integer domain id in [0, 232], got " + node.Scalar());
    return static_cast<std::uint32_t>(v);
  }

  std::chrono::milliseconds seconds_at(const YAML::Node& node, const std::string& key_path) const {
    const double s = number_at(node, key_path, 0, kMaxTimeoutS, true);
    return std::chrono::milliseconds(static_cast<std::int64_t>(std::llround(s * 1000)));
  }

  std::vector<std::string> strings_at(const YAML::Node& node, const std::string& key_path) const {
    if (!node.IsSequence()) fail(node, key_path, "expected a list of strings, got " + kind_of(node));
    std::vector<std::string> out;
    for (std::size_t i = 0; i < node.size(); ++i)
      out.push_back(string_at(node[i], key_path + "[" + std::to_string(i) + "]"));
    return out;
  }

  static std::string resolve(const fs::path& base, const std::string& path) {
    fs::path p(path);
    if (p.is_relative()) p = fs::absolute(base / p);
    std::string out = p.lexically_normal().string();
    while (out.size() > 1 && out.back() == '/') out.pop_back();  // "/repo/deploy/.." normalizes to "/repo/"
    return out;
  }

  ServiceDef service(const YAML::Node& key, const YAML::Node& node, const ComposeFile& file) const {
    if (!key.IsScalar()) fail(key, "services", "service names must be plain names, got " + kind_of(key));
    ServiceDef s;
    s.name = key.Scalar();
    s.line = line_of(key);
    const std::string p = "services." + s.name;
    if (!valid_service_name(s.name))
      fail(key, p,
           "service name '" + s.name +
               "' must be 1–64 letters, digits, '_', '-' or '.', starting with a letter or digit");
    if (!node.IsMap()) fail(node, p, "expected a mapping with at least 'binary:', got " + kind_of(node));
    check_keys(node, p + ".", kServiceKeys);

    if (!node["binary"]) fail(key, p + ".binary", "missing: every service needs the executable to run");
    const std::string binary = string_at(node["binary"], p + ".binary");
    if (binary.empty()) fail(node["binary"], p + ".binary", "expected a non-empty executable name or path");
    s.binary = binary.find('/') == std::string::npos ? resolve(file.bin_dir, binary) : resolve(file.root, binary);

    if (node["args"]) s.args = strings_at(node["args"], p + ".args");
    if (node["config"]) {
      const std::string config = string_at(node["config"], p + ".config");
      if (!config.empty()) s.config = resolve(file.root, config);
    }
    if (node["host"]) {
      s.host = string_at(node["host"], p + ".host");
      if (s.host.empty()) fail(node["host"], p + ".host", "expected a host name, got an empty string");
    }
    if (node["restart"]) {
      const std::string r = string_at(node["restart"], p + ".restart");
      if (r == "always")
        s.restart = RestartPolicy::kAlways;
      else if (r == "on-failure")
        s.restart = RestartPolicy::kOnFailure;
      else if (r == "no")
        s.restart = RestartPolicy::kNo;
      else
        fail(node["restart"], p + ".restart", "expected one of always, on-failure, no; got '" + r + "'");
    }
    if (node["depends_on"]) {
      s.depends_on = strings_at(node["depends_on"], p + ".depends_on");
      std::set<std::string> unique;
      for (std::size_t i = 0; i < s.depends_on.size(); ++i) {
        if (!unique.insert(s.depends_on[i]).second)
          fail(node["depends_on"][i], p + ".depends_on[" + std::to_string(i) + "]",
               "'" + s.depends_on[i] + "' listed twice");
      }
    }
    if (node["ready_timeout_s"]) s.ready_timeout = seconds_at(node["ready_timeout_s"], p + ".ready_timeout_s");
    if (node["stop_timeout_s"]) s.stop_timeout = seconds_at(node["stop_timeout_s"], p + ".stop_timeout_s");
    if (node["env"]) {
      const YAML::Node env = node["env"];
      if (!env.IsMap()) fail(env, p + ".env", "expected a mapping of variable name to value, got " + kind_of(env));
      std::vector<std::string> names;
      for (auto it = env.begin(); it != env.end(); ++it) {
        const std::string name = it->first.IsScalar() ? it->first.Scalar() : "";
        if (!valid_env_name(name)) fail(it->first, p + ".env", "'" + name + "' is not an environment variable name");
        if (s.env.count(name)) fail(it->first, p + ".env." + name, "variable given twice");
        s.env[name] = string_at(it->second, p + ".env." + name);
      }
    }
    if (node["description"]) s.description = string_at(node["description"], p + ".description");
    return s;
  }

  void check_dependencies(const YAML::Node& services, const ComposeFile& file) const {
    std::vector<ServiceDeps> graph;
    for (const auto& s : file.services) {
      const YAML::Node deps = services[s.name]["depends_on"];
      for (std::size_t i = 0; i < s.depends_on.size(); ++i) {
        if (!file.find(s.depends_on[i])) {
          fail(deps[i], "services." + s.name + ".depends_on[" + std::to_string(i) + "]",
               "unknown service '" + s.depends_on[i] + "' (services: " + names(file) + ")");
        }
      }
      graph.push_back({s.name, s.depends_on});
    }
    try {
      start_order(graph);
    } catch (const DependencyCycleError& e) {
      const std::string& first = e.cycle().front();
      fail(services[first]["depends_on"], "services." + first + ".depends_on", e.what());
    }
  }

  static std::string names(const ComposeFile& file) {
    std::vector<std::string> out;
    for (const auto& s : file.services) out.push_back(s.name);
    return join(out);
  }

  std::string file_;
  const ParseOptions& options_;
};

}  // namespace

const char* to_string(RestartPolicy policy) {
  switch (policy) {
    case RestartPolicy::kAlways: return "always";
    case RestartPolicy::kOnFailure: return "on-failure";
    case RestartPolicy::kNo: return "no";
  }
  return "?";
}

const ServiceDef* ComposeFile::find(const std::string& name) const {
  for (const auto& s : services)
    if (s.name == name) return &s;
  return nullptr;
}

std::string ComposeFile::display_path(const std::string& p) const {
  const std::string prefix = root.empty() || root.back() == '/' ? root : root + "/";
  if (!prefix.empty() && p.compare(0, prefix.size(), prefix) == 0) return p.substr(prefix.size());
  return p;
}

std::string ComposeFile::dds_uri() const { return dds_config.empty() ? "" : "file://" + dds_config; }

ComposeError::ComposeError(const std::string& file, int line, const std::string& key_path, const std::string& problem)
    : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : "") + ": " +
                         (key_path.empty() ? "" : key_path + ": ") + problem),
      file_(file),
      line_(line),
      key_path_(key_path) {}

std::optional<std::string> process_env(const std::string& name) {
  const char* v = std::getenv(name.c_str());
  if (!v) return std::nullopt;
  return std::string(v);
}

std::string expand_variables(const std::string& value, const EnvLookup& env) {
  std::string out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (value[i] != '$') {
      out += value[i];
      continue;
    }
    if (i + 1 < value.size() && value[i + 1] == '$') {
      out += '$';
      ++i;
      continue;
    }
    if (i + 1 >= value.size() || value[i + 1] != '{') {
      out += '$';  // a lone '$' stays as written
      continue;
    }
    const auto close = value.find('}', i + 2);
    if (close == std::string::npos)
      throw std::invalid_argument("unterminated '${' in '" + value + "' (write $$ for a literal '$')");
    const std::string inside = value.substr(i + 2, close - i - 2);
    const auto dflt = inside.find(":-");
    const std::string name = inside.substr(0, dflt);
    if (!valid_env_name(name)) throw std::invalid_argument("'${" + inside + "}' does not name an environment variable");
    const auto v = env ? env(name) : std::nullopt;
    if (v && !v->empty()) {
      out += *v;
    } else if (dflt != std::string::npos) {
      out += inside.substr(dflt + 2);
    } else {
      throw std::invalid_argument("environment variable " + name + " is not set (use ${" + name + ":-default})");
    }
    i = close;
  }
  return out;
}

ComposeFile parse_compose(const std::string& text, const std::string& path, const ParseOptions& options) {
  const std::string absolute = fs::absolute(fs::path(path)).lexically_normal().string();
  return Parser(absolute, options).parse(text);
}

ComposeFile load_compose(const std::string& path, const ParseOptions& options) {
  std::ifstream in(path);
  if (!in) throw ComposeError(path, 0, "", "cannot read the compose file (does it exist?)");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_compose(ss.str(), path, options);
}

bool is_local_host(const std::string& host, const std::vector<std::string>& this_host_names) {
  if (host == "localhost" || host == "127.0.0.1" || host == "::1") return true;
  return std::find(this_host_names.begin(), this_host_names.end(), host) != this_host_names.end();
}

}  // namespace rigger::compose
