// riggerctl's task commands: validate (offline), run, status, tree, skills, cancel, pause, resume, log.
// Each verb is in its own file (task_support.hpp lists them); here the command line.
#include <memory>
#include <string>
#include <tuple>

#include "commands.hpp"
#include "rigger/base/install.hpp"
#include "task_support.hpp"

namespace rigger::ctl {

using namespace tasks;

void add_task_commands(CLI::App& app, const CommonOptions& common, int& exit_code) {
  {
    auto* cmd = app.add_subcommand("validate", "Validate a recipe offline against a skill-library file (exit 0/1).");
    auto file = std::make_shared<std::string>();
    auto library =
        std::make_shared<std::string>(find_data_path("recipes/examples/skill_library.json").path.string());
    cmd->add_option("FILE", *file, "recipe file")->required();
    cmd->add_option("--library", *library,
                    "skill-library file (default: recipes/examples/skill_library.json of the installation)");
    cmd->callback([file, library, &exit_code] { exit_code = validate(*file, *library); });
  }
  {
    auto* cmd = app.add_subcommand("run", "Submit a recipe, show the live tree, exit 0 on SUCCEEDED.");
    auto opt = std::make_shared<RunOptions>();
    cmd->add_option("FILE", opt->file, "recipe file")->required();
    cmd->add_option("--task-id", opt->task_id, "submit under this task id (re-running a file needs a new id)");
    cmd->add_option("--timeout", opt->timeout_s, "give up waiting after S seconds (0: never)");
    cmd->add_option("--match-timeout", opt->match_timeout_s, "wait this long for the task controller");
    cmd->add_flag("--quiet", opt->quiet, "print only task state changes");
    cmd->callback([opt, &common, &exit_code] { exit_code = run_recipe(common, *opt); });
  }
  auto timeout = std::make_shared<double>(5.0);
  {
    auto* cmd = app.add_subcommand("status", "List the tasks the controller's journal knows, newest first.");
    cmd->add_option("--timeout", *timeout, "seconds to wait for the controller");
    cmd->callback([timeout, &common, &exit_code] { exit_code = journal_query(common, "", *timeout); });
  }
  {
    auto* cmd = app.add_subcommand("log", "The journal's timeline of a task.");
    auto task = std::make_shared<std::string>();
    cmd->add_option("TASK", *task, "task id")->required();
    cmd->add_option("--timeout", *timeout, "seconds to wait for the controller");
    cmd->callback([task, timeout, &common, &exit_code] { exit_code = journal_query(common, *task, *timeout); });
  }
  {
    auto* cmd = app.add_subcommand("tree", "The last status of every node of a task.");
    auto task = std::make_shared<std::string>();
    cmd->add_option("TASK", *task, "task id")->required();
    cmd->add_option("--timeout", *timeout, "seconds to wait for the controller");
    cmd->callback([task, timeout, &common, &exit_code] { exit_code = show_tree(common, *task, *timeout); });
  }
  {
    auto* cmd = app.add_subcommand("skills", "Live executors and the skills and monitors they offer.");
    cmd->add_option("--timeout", *timeout, "seconds to wait for an executor");
    cmd->callback([timeout, &common, &exit_code] { exit_code = show_skills(common, *timeout); });
  }
  {
    auto* cmd = app.add_subcommand("cancel", "Cancel a running task and wait until it stopped.");
    auto task = std::make_shared<std::string>();
    auto reason = std::make_shared<std::string>("canceled from riggerctl");
    cmd->add_option("TASK", *task, "task id")->required();
    cmd->add_option("--reason", *reason, "why (journalled)");
    cmd->add_option("--timeout", *timeout, "seconds to wait for the task to end");
    cmd->callback([task, reason, timeout, &common, &exit_code] {
      exit_code = task_command(common, *task, rigger_task_TASK_CANCEL, *reason, *timeout);
    });
  }
  for (const auto& [verb, kind, help] :
       {std::tuple<const char*, rigger_task_TaskCommandKind, const char*>{
            "pause", rigger_task_TASK_PAUSE, "Pause a running task (no new leaf starts) and wait until it is PAUSED."},
        {"resume", rigger_task_TASK_RESUME,
         "Resume a paused task and wait until it is RUNNING again; or an INTERRUPTED task (the controller "
         "restarted while it ran): print what was done and what will run, which starts once the operator "
         "confirms."}}) {
    auto* cmd = app.add_subcommand(verb, help);
    auto task = std::make_shared<std::string>();
    auto reason = std::make_shared<std::string>(std::string(verb) + "d from riggerctl");
    auto wait_s = std::make_shared<double>(10.0);
    cmd->add_option("TASK", *task, "task id")->required();
    cmd->add_option("--reason", *reason, "why (journalled)");
    cmd->add_option("--timeout", *wait_s, "seconds to wait for the acknowledgement");
    const auto k = kind;
    cmd->callback([task, reason, wait_s, k, &common, &exit_code] {
      exit_code = task_command(common, *task, k, *reason, *wait_s);
    });
  }
}

}  // namespace rigger::ctl
