#include "rigger/compose/compose_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>

namespace rigger::compose {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

const std::string kFile = "/repo/deploy/compose.yaml";

ParseOptions with_env(std::map<std::string, std::string> vars) {
  ParseOptions opt;
  opt.env = [vars](const std::string& name) -> std::optional<std::string> {
    auto it = vars.find(name);
    if (it == vars.end()) return std::nullopt;
    return it->second;
  };
  return opt;
}

ComposeFile parse(const std::string& text, const ParseOptions& opt = with_env({})) {
  return parse_compose(text, kFile, opt);
}

// Parses `text`, which must fail, and returns the error.
ComposeError parse_error(const std::string& text, const ParseOptions& opt = with_env({})) {
  try {
    parse(text, opt);
  } catch (const ComposeError& e) {
    return e;
  }
  ADD_FAILURE() << "parsed without error:\n" << text;
  return ComposeError("", 0, "", "");
}

TEST(ComposeFileTest, ParsesAFullServiceAndResolvesPathsAgainstTheRoot) {
  const auto f = parse(R"(
dds: {domain: 7, config: deploy/cyclonedds.xml}
services:
  cell_sim:
    binary: cell_sim
    args: [--realtime, 2]
    config: deploy/config/cell_sim.json
    host: cell-robot
    restart: always
    ready_timeout_s: 20
    stop_timeout_s: 2.5
    env: {MUJOCO_GL: egl}
    description: the simulated cell
  gateway:
    binary: tools/bin/gw
    depends_on: [cell_sim]
)");
  EXPECT_EQ(f.path, kFile);
  EXPECT_EQ(f.root, "/repo");
  EXPECT_EQ(f.domain, 7u);
  EXPECT_EQ(f.dds_config, "/repo/deploy/cyclonedds.xml");
  EXPECT_EQ(f.dds_uri(), "file:///repo/deploy/cyclonedds.xml");
  EXPECT_EQ(f.log_dir, "/tmp/rigger-compose/7");
  EXPECT_EQ(f.bin_dir, "/repo/build/bin");
  ASSERT_EQ(f.services.size(), 2u);
  const auto& s = f.services[0];
  EXPECT_EQ(s.name, "cell_sim");
  EXPECT_EQ(s.binary, "/repo/build/bin/cell_sim");
  EXPECT_THAT(s.args, ElementsAre("--realtime", "2"));
  EXPECT_EQ(s.config, "/repo/deploy/config/cell_sim.json");
  EXPECT_EQ(s.host, "cell-robot");
  EXPECT_EQ(s.restart, RestartPolicy::kAlways);
  EXPECT_EQ(s.ready_timeout, std::chrono::milliseconds(20000));
  EXPECT_EQ(s.stop_timeout, std::chrono::milliseconds(2500));
  EXPECT_EQ(s.env.at("MUJOCO_GL"), "egl");
  EXPECT_EQ(s.description, "the simulated cell");
  EXPECT_EQ(s.line, 4);
  const auto& g = f.services[1];
  EXPECT_EQ(g.binary, "/repo/tools/bin/gw");  // a path with '/' is relative to the root, not bin_dir
  EXPECT_THAT(g.depends_on, ElementsAre("cell_sim"));
  EXPECT_EQ(f.display_path(g.binary), "tools/bin/gw");
  EXPECT_EQ(f.display_path("/elsewhere/x"), "/elsewhere/x");
}

TEST(ComposeFileTest, DefaultsForAMinimalService) {
  const auto f = parse("services:\n  a: {binary: echo}\n");
  ASSERT_EQ(f.services.size(), 1u);
  const auto& s = f.services[0];
  EXPECT_EQ(f.domain, 0u);
  EXPECT_TRUE(f.dds_config.empty());
  EXPECT_EQ(f.dds_uri(), "");
  EXPECT_EQ(s.host, "localhost");
  EXPECT_EQ(s.restart, RestartPolicy::kOnFailure);
  EXPECT_EQ(s.ready_timeout, std::chrono::milliseconds(10000));
  EXPECT_EQ(s.stop_timeout, std::chrono::milliseconds(5000));
  EXPECT_TRUE(s.config.empty());
  EXPECT_TRUE(s.args.empty());
  EXPECT_TRUE(s.depends_on.empty());
}

// rigger-compose passes its own folder: a file without bin_dir runs the binaries installed beside it.
TEST(ComposeFileTest, BinDirDefaultsToTheGivenFolder) {
  ParseOptions opt = with_env({});
  opt.default_bin_dir = "/opt/rigger/bin";
  const auto f = parse("services:\n  a: {binary: echo}\n", opt);
  EXPECT_EQ(f.bin_dir, "/opt/rigger/bin");
  EXPECT_EQ(f.services[0].binary, "/opt/rigger/bin/echo");
  const auto g = parse("bin_dir: out/bin\nservices:\n  a: {binary: echo}\n", opt);  // the file wins
  EXPECT_EQ(g.bin_dir, "/repo/out/bin");
}

TEST(ComposeFileTest, RootBinDirAndLogDirAreConfigurable) {
  const auto f = parse("root: /abs/cell\nbin_dir: out/bin\nlog_dir: logs\nservices:\n  a: {binary: echo}\n");
  EXPECT_EQ(f.root, "/abs/cell");
  EXPECT_EQ(f.bin_dir, "/abs/cell/out/bin");
  EXPECT_EQ(f.log_dir, "/abs/cell/logs");
  EXPECT_EQ(f.services[0].binary, "/abs/cell/out/bin/echo");
  // A relative root is relative to the file's folder.
  const auto g = parse("root: .\nservices:\n  a: {binary: echo}\n");
  EXPECT_EQ(g.root, "/repo/deploy");
}

TEST(ComposeFileTest, KeepsTheFileOrderOfServices) {
  const auto f = parse("services:\n  zeta: {binary: a}\n  alpha: {binary: b}\n  mid: {binary: c}\n");
  ASSERT_EQ(f.services.size(), 3u);
  EXPECT_EQ(f.services[0].name, "zeta");
  EXPECT_EQ(f.services[1].name, "alpha");
  EXPECT_EQ(f.services[2].name, "mid");
  EXPECT_EQ(f.find("mid"), &f.services[2]);
  EXPECT_EQ(f.find("nope"), nullptr);
}

TEST(ComposeFileTest, DomainOverrideAlsoMovesTheDefaultLogDir) {
  ParseOptions opt = with_env({});
  opt.domain = 42;
  const auto f = parse("dds: {domain: 3}\nservices:\n  a: {binary: echo}\n", opt);
  EXPECT_EQ(f.domain, 42u);
  EXPECT_EQ(f.log_dir, "/tmp/rigger-compose/42");
}

TEST(ComposeFileTest, RestartPolicyNoIsAcceptedPlainOrQuoted) {
  const auto f = parse(
      "services:\n  a: {binary: x, restart: no}\n  b: {binary: x, restart: 'no'}\n  c: {binary: x, restart: "
      "on-failure}\n");
  EXPECT_EQ(f.services[0].restart, RestartPolicy::kNo);
  EXPECT_EQ(f.services[1].restart, RestartPolicy::kNo);
  EXPECT_EQ(f.services[2].restart, RestartPolicy::kOnFailure);
}

TEST(ComposeFileTest, ExpandsEnvironmentVariables) {
  const auto f = parse(R"(
bin_dir: ${BUILD:-build}/bin
dds: {domain: "${DOMAIN:-0}"}
services:
  a: {binary: echo, args: ["${MODE}", "cost $$5", "lone $ sign"], env: {X: "${HOME_DIR}/x"}}
)",
                       with_env({{"DOMAIN", "12"}, {"MODE", "fast"}, {"HOME_DIR", "/h"}}));
  EXPECT_EQ(f.bin_dir, "/repo/build/bin");  // unset: the default
  EXPECT_EQ(f.domain, 12u);
  EXPECT_THAT(f.services[0].args, ElementsAre("fast", "cost $5", "lone $ sign"));
  EXPECT_EQ(f.services[0].env.at("X"), "/h/x");
}

TEST(ComposeFileTest, ExpandVariablesRejectsUnsetAndBrokenSyntax) {
  const EnvLookup none = [](const std::string&) { return std::nullopt; };
  EXPECT_EQ(expand_variables("${A:-}", none), "");
  EXPECT_THROW(expand_variables("${A}", none), std::invalid_argument);
  EXPECT_THROW(expand_variables("${A", none), std::invalid_argument);
  EXPECT_THROW(expand_variables("${1A}", none), std::invalid_argument);
  const auto e = parse_error("services:\n  a: {binary: \"${NOT_SET}\"}\n");
  EXPECT_EQ(e.key_path(), "services.a.binary");
  EXPECT_THAT(e.what(), HasSubstr("NOT_SET is not set"));
}

TEST(ComposeFileTest, UnknownKeysAreErrorsWithLineAndPath) {
  auto e = parse_error("services:\n  a:\n    binary: echo\n    restrat: always\n");
  EXPECT_EQ(e.file(), kFile);
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(e.key_path(), "services.a.restrat");
  EXPECT_THAT(e.what(), HasSubstr("unknown key 'restrat'"));
  EXPECT_THAT(e.what(), HasSubstr("restart"));  // lists what is expected
  EXPECT_THAT(e.what(), HasSubstr(kFile + ":4: services.a.restrat:"));

  e = parse_error("servicez:\n  a: {binary: echo}\n");
  EXPECT_EQ(e.key_path(), "servicez");
  e = parse_error("dds: {domain: 1, uri: x}\nservices:\n  a: {binary: echo}\n");
  EXPECT_EQ(e.key_path(), "dds.uri");
}

TEST(ComposeFileTest, DuplicateKeysAreErrors) {
  auto e = parse_error("services:\n  a: {binary: echo}\n  a: {binary: other}\n");
  EXPECT_EQ(e.key_path(), "services.a");
  EXPECT_THAT(e.what(), HasSubstr("first on line 2"));
  e = parse_error("services:\n  a:\n    binary: echo\n    binary: other\n");
  EXPECT_EQ(e.key_path(), "services.a.binary");
}

TEST(ComposeFileTest, WrongTypesAndValuesAreExplained) {
  struct Case {
    const char* yaml;
    const char* key_path;
    const char* expected;
  };
  const Case cases[] = {
      {"services:\n  a: {binary: [x]}\n", "services.a.binary", "expected a string"},
      {"services:\n  a: {binary: ''}\n", "services.a.binary", "non-empty"},
      {"services:\n  a: {args: [x]}\n", "services.a.binary", "missing"},
      {"services:\n  a: {binary: x, args: --flag}\n", "services.a.args", "expected a list of strings"},
      {"services:\n  a: {binary: x, args: [[1]]}\n", "services.a.args[0]", "expected a string"},
      {"services:\n  a: {binary: x, restart: sometimes}\n", "services.a.restart", "always, on-failure, no"},
      {"services:\n  a: {binary: x, ready_timeout_s: 0}\n", "services.a.ready_timeout_s", "(0, 3600]"},
      {"services:\n  a: {binary: x, stop_timeout_s: -1}\n", "services.a.stop_timeout_s", "(0, 3600]"},
      {"services:\n  a: {binary: x, stop_timeout_s: soon}\n", "services.a.stop_timeout_s", "got 'soon'"},
      {"services:\n  a: {binary: x, host: ''}\n", "services.a.host", "host name"},
      {"services:\n  a: {binary: x, env: [A]}\n", "services.a.env", "mapping"},
      {"services:\n  a: {binary: x, env: {1A: v}}\n", "services.a.env", "not an environment variable name"},
      {"services:\n  a: {binary: x, depends_on: b}\n", "services.a.depends_on", "list"},
      {"services:\n  a b: {binary: x}\n", "services.a b", "service name"},
      {"services:\n  a: echo\n", "services.a", "expected a mapping"},
      {"dds: {domain: 233}\nservices:\n  a: {binary: x}\n", "dds.domain", "[0, 232]"},
      {"dds: {domain: 1.5}\nservices:\n  a: {binary: x}\n", "dds.domain", "integer"},
      {"dds: 5\nservices:\n  a: {binary: x}\n", "dds", "mapping"},
      {"services: {}\n", "services", "mapping of service name"},
      {"dds: {domain: 1}\n", "services", "missing"},
      {"- a\n- b\n", "", "expected a mapping"},
      {"", "", "expected a mapping"},
  };
  for (const auto& c : cases) {
    const auto e = parse_error(c.yaml);
    EXPECT_EQ(e.key_path(), c.key_path) << c.yaml;
    EXPECT_THAT(e.what(), HasSubstr(c.expected)) << c.yaml;
  }
}

TEST(ComposeFileTest, YamlSyntaxErrorsNameTheLine) {
  const auto e = parse_error("services:\n  a: {binary: x\n  b: {binary: y}\n");
  EXPECT_GT(e.line(), 0);
  EXPECT_THAT(e.what(), HasSubstr("not valid YAML"));
}

TEST(ComposeFileTest, UnknownDependencyIsAnErrorAtItsEntry) {
  const auto e = parse_error("services:\n  a: {binary: x}\n  b:\n    binary: x\n    depends_on: [a, c]\n");
  EXPECT_EQ(e.key_path(), "services.b.depends_on[1]");
  EXPECT_EQ(e.line(), 5);
  EXPECT_THAT(e.what(), HasSubstr("unknown service 'c'"));
  EXPECT_THAT(e.what(), HasSubstr("services: a, b"));
}

TEST(ComposeFileTest, DependencyListedTwiceIsAnError) {
  const auto e = parse_error("services:\n  a: {binary: x}\n  b: {binary: x, depends_on: [a, a]}\n");
  EXPECT_EQ(e.key_path(), "services.b.depends_on[1]");
}

TEST(ComposeFileTest, DependencyCyclesAreErrorsThatShowTheCycle) {
  auto e = parse_error(
      "services:\n  a: {binary: x, depends_on: [c]}\n  b: {binary: x, depends_on: [a]}\n  c: {binary: x, depends_on: "
      "[b]}\n");
  EXPECT_EQ(e.key_path(), "services.a.depends_on");
  EXPECT_THAT(e.what(), HasSubstr("dependency cycle: a -> c -> b -> a"));
  e = parse_error("services:\n  a: {binary: x, depends_on: [a]}\n");
  EXPECT_THAT(e.what(), HasSubstr("a -> a"));
}

TEST(ComposeFileTest, LoadReportsAMissingFile) {
  try {
    load_compose("/nonexistent/compose.yaml");
    FAIL() << "no error";
  } catch (const ComposeError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/compose.yaml");
    EXPECT_THAT(e.what(), HasSubstr("cannot read"));
  }
}

TEST(ComposeFileTest, LocalHostNames) {
  EXPECT_TRUE(is_local_host("localhost", {}));
  EXPECT_TRUE(is_local_host("127.0.0.1", {}));
  EXPECT_TRUE(is_local_host("cell-robot", {"cell-robot", "vm"}));
  EXPECT_FALSE(is_local_host("cell-crane", {"cell-robot", "vm"}));
}

// The shipped file must stay valid and describe the simulated cell.
TEST(ComposeFileTest, TheShippedComposeFileIsValid) {
  const auto f = load_compose(std::string(RIGGER_SOURCE_DIR) + "/deploy/compose.yaml", with_env({}));
  EXPECT_EQ(f.root, std::string(RIGGER_SOURCE_DIR));
  EXPECT_EQ(f.dds_config, std::string(RIGGER_SOURCE_DIR) + "/deploy/cyclonedds.xml");
  for (const char* name :
       {"cell_sim", "crane_gateway", "world_model", "vision_tracker", "admittance_control", "monitor_host",
        "robot-skills", "perception-skills", "operator-skills", "task_controller", "scripted_operator"}) {
    const auto* s = f.find(name);
    ASSERT_NE(s, nullptr) << name;
    EXPECT_EQ(s->host, "localhost") << name;
  }
  for (const char* id : {"robot-skills", "perception-skills", "operator-skills"}) {
    EXPECT_EQ(f.find(id)->binary, f.bin_dir + "/skill_executor");
    EXPECT_EQ(f.find(id)->config, std::string(RIGGER_SOURCE_DIR) + "/deploy/config/" + id + ".json");
  }
}

}  // namespace
}  // namespace rigger::compose
