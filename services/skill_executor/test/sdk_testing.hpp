#pragma once
// The SDK's fakes and run harness under the name these tests use (testing::RunHarness, testing::FakeRobot…).
#include "rigger/skill_sdk/testing/cell_fakes.hpp"
#include "rigger/skill_sdk/testing/run_harness.hpp"
#include "skills/sdk.hpp"

namespace rigger::skill_executor {
namespace testing = rigger::skill_sdk::testing;
}  // namespace rigger::skill_executor
