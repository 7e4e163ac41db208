// Benchmarks of the task controller's pure logic (Google Benchmark; built when
// RIGGER_BUILD_BENCH is on, not a test). The scale target: validate and build a
// 10,000-node recipe in < 200 ms; 1,000 concurrent monitor leaves in one Parallel.
//
//   build/bin/task_controller_bench [--benchmark_filter=…]

#include <algorithm>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "rigger/bt/engine.hpp"
#include "rigger/bt/tree_builder.hpp"
#include "rigger/recipe/recipe_schema.hpp"
#include "rigger/recipe/recipe_validator.hpp"
#include "rigger/base/bounded_json.hpp"
#include "../test/scale_recipes.hpp"

namespace {

using namespace rigger;
using Json = nlohmann::json;

const skill::SkillLibrary& library() {
  static const skill::SkillLibrary kLibrary =
      skill::SkillLibrary::load_file(std::string(RIGGER_SOURCE_DIR) + "/test/data/scripted_skill_library.json");
  return kLibrary;
}

using testing::big_recipe;

class NullPort : public bt::Port {
 public:
  bt::TimePoint now() override { return {}; }
  void start_leaf(const bt::NodeSpec&, bt::Activation) override {}
  void shutdown_leaf(const bt::NodeSpec&, bt::Activation, const std::string&) override {}
  void evaluate_condition(const bt::NodeSpec&, bt::Activation) override {}
  void ask_operator(const bt::NodeSpec&, bt::Activation) override {}
  void withdraw_operator_request(const bt::NodeSpec&, bt::Activation) override {}
  void schedule(bt::TimerId, bt::TimePoint) override {}
  void cancel_timer(bt::TimerId) override {}
  void escalate_safe_stop(const bt::NodeSpec&, const std::string&) override {}
  void node_changed(const bt::NodeSpec&, const bt::NodeStatus&) override {}
  void finished(const bt::TaskResult&) override {}
};

void BM_ValidateAndBuild10kNodes(benchmark::State& state) {
  const std::string text = big_recipe(1111).dump();  // 10,000 nodes
  const recipe::RecipeValidator validator(library());
  NullPort port;
  for (auto _ : state) {
    auto result = validator.validate_text(text);
    if (!result.ok()) {
      state.SkipWithError("recipe rejected");
      break;
    }
    bt::Engine engine(std::move(result.recipe->tree), port);
    benchmark::DoNotOptimize(engine);
  }
  state.counters["bytes"] = static_cast<double>(text.size());
}
BENCHMARK(BM_ValidateAndBuild10kNodes)->Unit(benchmark::kMillisecond);

void BM_Stage_Parse10kNodes(benchmark::State& state) {
  const std::string text = big_recipe(1111).dump();
  for (auto _ : state) {
    benchmark::DoNotOptimize(rigger::parse_json_bounded(text));
  }
}
BENCHMARK(BM_Stage_Parse10kNodes)->Unit(benchmark::kMillisecond);

void BM_Stage_Schema10kNodes(benchmark::State& state) {
  const Json document = big_recipe(1111);
  for (auto _ : state) {
    benchmark::DoNotOptimize(recipe::SchemaValidator::recipe().validate(document));
  }
}
BENCHMARK(BM_Stage_Schema10kNodes)->Unit(benchmark::kMillisecond);

void BM_Stage_EngineConstruct10kNodes(benchmark::State& state) {
  const auto validated = recipe::RecipeValidator(library()).validate_document(big_recipe(1111));
  NullPort port;
  for (auto _ : state) {
    bt::Engine engine(validated.recipe->tree, port);
    benchmark::DoNotOptimize(engine);
  }
}
BENCHMARK(BM_Stage_EngineConstruct10kNodes)->Unit(benchmark::kMillisecond);

// What the controller's Task adds to building a 10,000-node recipe: every remote leaf's START parameters
// serialised once, up front, instead of on each START (reaction latency).
void BM_Stage_SerialiseLeafParams10kNodes(benchmark::State& state) {
  const auto validated = recipe::RecipeValidator(library()).validate_document(big_recipe(1111));
  const auto& nodes = validated.recipe->tree.nodes;
  std::size_t leaves = 0;
  for (auto _ : state) {
    std::vector<std::string> texts;
    texts.reserve(nodes.size());
    for (const auto& node : nodes)
      texts.push_back(bt::is_remote_leaf(node.kind) ? node.params.dump() : std::string());
    leaves = static_cast<std::size_t>(
        std::count_if(texts.begin(), texts.end(), [](const std::string& t) { return !t.empty(); }));
    benchmark::DoNotOptimize(texts);
  }
  state.counters["leaves"] = static_cast<double>(leaves);
}
BENCHMARK(BM_Stage_SerialiseLeafParams10kNodes)->Unit(benchmark::kMillisecond);

// 1,000 monitors beside one skill: start everything, a monitor fires, all stop, the Parallel reports.
void BM_Parallel1000MonitorsFireAndStop(benchmark::State& state) {
  const bt::TreeSpec spec = testing::skill_beside_monitors(1000);
  NullPort port;
  for (auto _ : state) {
    state.PauseTiming();
    bt::Engine engine(spec, port);
    state.ResumeTiming();
    engine.start();
    engine.on_leaf_event("root/500", {bt::LeafEventKind::kFailure, 1, "FORCE_LIMIT", "", std::nullopt});
    for (std::size_t i = 0; i <= 1000; ++i) {
      if (i != 500) {
        engine.on_leaf_event("root/" + std::to_string(i), {bt::LeafEventKind::kStopped, 1, "", "", std::nullopt});
      }
    }
    if (!engine.result()) {
      state.SkipWithError("did not finish");
      break;
    }
  }
}
BENCHMARK(BM_Parallel1000MonitorsFireAndStop)->Unit(benchmark::kMicrosecond);

// The cost of the decisive event alone: a monitor's FAILURE → SHUTDOWN of its 1,000 siblings.
void BM_MonitorFailureToShutdowns1000(benchmark::State& state) {
  const bt::TreeSpec spec = testing::skill_beside_monitors(1000);
  NullPort port;
  for (auto _ : state) {
    state.PauseTiming();
    bt::Engine engine(spec, port);
    engine.start();
    state.ResumeTiming();
    engine.on_leaf_event("root/500", {bt::LeafEventKind::kFailure, 1, "FORCE_LIMIT", "", std::nullopt});
  }
}
BENCHMARK(BM_MonitorFailureToShutdowns1000)->Unit(benchmark::kMicrosecond);

// One leaf event in the paper's pattern: skill ‖ 3 monitors, the skill succeeds (Repeat restarts it).
void BM_LeafEventDispatch(benchmark::State& state) {
  namespace b = bt::build;
  const bt::TreeSpec spec = b::build(b::repeat(
      1'000'000'000, b::parallel(1, 1, {b::skill("Attach"), b::monitor("Yank"), b::monitor("Force"), b::monitor("Timer")})));
  NullPort port;
  bt::Engine engine(spec, port);
  engine.start();
  const auto skill_index = *engine.find("root/0/0");
  for (auto _ : state) {
    // SUCCESS of the skill, then STOPPED of the three monitors: the Parallel succeeds and restarts.
    const bt::Activation a = engine.status(skill_index).activation;
    engine.on_leaf_event("root/0/0", {bt::LeafEventKind::kSuccess, a, "", "", std::nullopt});
    for (const char* id : {"root/0/1", "root/0/2", "root/0/3"}) {
      engine.on_leaf_event(id, {bt::LeafEventKind::kStopped, a, "", "", std::nullopt});
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 4);
}
BENCHMARK(BM_LeafEventDispatch)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
