// The rehearsal cell brought to the real cell's revision, in-process on a private domain: a fake world
// model (the test's reader of rigger/world/cell_request, writers of cell_reply and cell) refuses a
// revision, accepts one and reports it later, and is missing; RehearsalRevision says when it may send.
#include <optional>

#include <gtest/gtest.h>

#include "rehearsal_revision.hpp"
#include "rigger/protocol/system.hpp"
#include "rigger/testing/domain.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::console {
namespace {

using namespace std::chrono_literals;

class RehearsalRevisionTest : public ::testing::Test {
 protected:
  RehearsalRevisionTest() {
    for (const dds_entity_t reader : revision_.readers()) loop_.on_data(reader, [this] { revision_.take(); });
  }

  /// Answers the last request seen as a world model would.
  void reply(bool ok, const std::string& code, const std::string& message) {
    world_protocol::CellReply r;
    r.client_id = seen_.back().client_id;
    r.request_id = seen_.back().request_id;
    r.ok = ok;
    r.code = code;
    r.message = message;
    rigger_world_CellReply wire{};
    world_protocol::to_wire(r, wire);
    ASSERT_EQ(replies_.write(wire), DDS_RETCODE_OK);
  }
  void report(const std::string& sha256, std::uint64_t number = 1) {
    world_protocol::CellRevision r;
    r.cell_revision = number;
    r.cell_json = "{}";
    r.sha256 = sha256;
    rigger_world_CellRevision wire{};
    world_protocol::to_wire(r, wire);
    ASSERT_EQ(revisions_.write(wire), DDS_RETCODE_OK);
  }
  /// The world model's reader of cell requests appears (discovery then matches it).
  void start_world_model() {
    requests_ = dds::Reader<rigger_world_CellRequest>(participant_, protocol::world::kCellRequest);
    loop_.on_data(requests_, [this] {
      requests_.take([this](const rigger_world_CellRequest& w, const dds_sample_info_t&) {
        seen_.push_back(world_protocol::from_wire(w));
      });
    });
    ASSERT_TRUE(loop_.run_until([&] { return revision_.world_model(); }, 5s));
  }

  testing::DomainLease lease_;
  dds::Participant participant_{lease_.id()};
  dds::EventLoop loop_{participant_};
  RehearsalRevision revision_{participant_, loop_, "console-test", 2s};
  dds::Reader<rigger_world_CellRequest> requests_;
  dds::Writer<rigger_world_CellReply> replies_{participant_, protocol::world::kCellReply};
  dds::Writer<rigger_world_CellRevision> revisions_{participant_, protocol::world::kCell};
  std::vector<world_protocol::CellRequest> seen_;
  const CellTarget target_{3, "sha-of-3", R"({"cell_version": 1})", {}};
};

TEST_F(RehearsalRevisionTest, ARefusedRevisionIsNotRunWithTheWorldModelsReason) {
  start_world_model();
  std::optional<std::string> done;
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(loop_.run_until([&] { return !seen_.empty(); }, 5s));
  EXPECT_EQ(seen_.back().op, world_protocol::CellOp::kApply);
  EXPECT_EQ(seen_.back().cell_json, target_.cell_json);
  EXPECT_EQ(seen_.back().who, "console:ada");
  EXPECT_FALSE(seen_.back().dry_run);
  reply(false, "INVALID", "/entities/2/pose: expected position_m");
  ASSERT_TRUE(loop_.run_until([&] { return done.has_value(); }, 5s));
  EXPECT_EQ(*done,
            "the rehearsal world model refused the cell's revision 3: INVALID: /entities/2/pose: expected "
            "position_m");
}

TEST_F(RehearsalRevisionTest, AnAcceptedRevisionRunsOnlyOnceTheWorldModelReportsIt) {
  start_world_model();
  report("sha-of-the-file");
  ASSERT_TRUE(loop_.run_until([&] { return revision_.running_sha256() == "sha-of-the-file"; }, 5s));
  std::optional<std::string> done;
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(loop_.run_until([&] { return !seen_.empty(); }, 5s));
  reply(true, "ACCEPTED", "revision 2");
  EXPECT_FALSE(loop_.run_until([&] { return done.has_value(); }, 300ms)) << "accepted, not yet reported";
  report(target_.sha256);
  ASSERT_TRUE(loop_.run_until([&] { return done.has_value(); }, 5s));
  EXPECT_EQ(*done, "");
  // Already running it: the next rehearsal sends nothing to the world model.
  done.reset();
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(*done, "");
  EXPECT_EQ(seen_.size(), 1u);
}

// A freshly started rehearsal cell may answer that the document runs already (UNCHANGED) before its
// report of that revision reached the console: the report that comes next is the one to wait for.
TEST_F(RehearsalRevisionTest, UnchangedBeforeAnyReportRunsOnceTheRevisionIsReported) {
  start_world_model();
  std::optional<std::string> done;
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(loop_.run_until([&] { return !seen_.empty(); }, 5s));
  reply(false, "UNCHANGED", "the document equals the running revision 1's");
  EXPECT_FALSE(loop_.run_until([&] { return done.has_value(); }, 300ms)) << "nothing reported yet";
  report("sha-of-the-same-document-as-another-text");
  ASSERT_TRUE(loop_.run_until([&] { return done.has_value(); }, 5s));
  EXPECT_EQ(*done, "");
}

// The simulator of the rehearsal cell follows the world model: the rehearsal runs once it says it runs on
// the same revision, and not at all when it refused it (a revision that reshapes the crane's load: the
// link then restarts the cell on it, rigger_rehearsal_new_load_test); forgotten for a restarted cell.
TEST_F(RehearsalRevisionTest, ARevisionTheSimulatorRefusedIsNotRehearsed) {
  dds::Writer<rigger_system_ServiceState> states(participant_, protocol::system::kServiceState);
  const auto simulator_says = [&](const std::string& detail) {
    rigger_system_ServiceState s{};
    s.service_id = const_cast<char*>("cell_sim");
    s.kind = const_cast<char*>("cell_sim");
    s.detail = const_cast<char*>(detail.c_str());
    ASSERT_EQ(states.write(s), DDS_RETCODE_OK);
  };
  start_world_model();
  simulator_says("cell revision 1");
  std::optional<std::string> done;
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(loop_.run_until([&] { return !seen_.empty(); }, 5s));
  reply(true, "ACCEPTED", "revision 2");
  report(target_.sha256, 2);
  EXPECT_FALSE(loop_.run_until([&] { return done.has_value(); }, 300ms)) << "the simulator has not said yet";
  simulator_says("refused cell revision 2: it reshapes the crane's load load: restart it on the new cell");
  ASSERT_TRUE(loop_.run_until([&] { return done.has_value(); }, 5s));
  EXPECT_NE(done->find("the rehearsal cell's simulator refused cell revision 2: it reshapes the crane's load"),
            std::string::npos) << *done;
  EXPECT_TRUE(revision_.simulator_refused());
  // Asked again while the world model runs it: still refused, nothing sent.
  done.reset();
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(loop_.run_until([&] { return done.has_value(); }, 5s));
  EXPECT_NE(done->find("refused cell revision 2"), std::string::npos) << *done;
  EXPECT_EQ(seen_.size(), 1u);
  // Once it runs on it, the rehearsal goes ahead.
  simulator_says("cell revision 2");
  ASSERT_TRUE(loop_.run_until([&] { return revision_.simulator_detail() == "cell revision 2"; }, 5s));
  done.reset();
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(loop_.run_until([&] { return done.has_value(); }, 5s));
  EXPECT_EQ(*done, "");
  EXPECT_FALSE(revision_.simulator_refused());
  // A restarted cell: what the old one said counts no more, the revision is applied again.
  revision_.forget();
  EXPECT_EQ(revision_.running_sha256(), "");
  EXPECT_EQ(revision_.simulator_detail(), "");
  done.reset();
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(loop_.run_until([&] { return seen_.size() == 2; }, 5s));
  EXPECT_FALSE(done.has_value());
}

TEST_F(RehearsalRevisionTest, NoWorldModelOrNoReportIsNotRunEither) {
  std::optional<std::string> done;
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(done.has_value());
  EXPECT_NE(done->find("no world model answers cell requests on the rehearsal domain"), std::string::npos) << *done;

  start_world_model();
  done.reset();
  revision_.bring_to(target_, "console:ada", [&](const std::string& error) { done = error; });
  ASSERT_TRUE(loop_.run_until([&] { return !seen_.empty(); }, 5s));
  reply(true, "ACCEPTED", "revision 2");
  ASSERT_TRUE(loop_.run_until([&] { return done.has_value(); }, 10s));
  EXPECT_EQ(*done, "the rehearsal world model did not report the revision it accepted within 2.00 s");
}

}  // namespace
}  // namespace rigger::console
