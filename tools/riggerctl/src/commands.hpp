#pragma once
/// @file
/// riggerctl's commands. Each `add_*` registers a subcommand on the app; the callback it installs
/// returns the process exit code through `exit_code`.

#include <string>

#include <CLI/CLI.hpp>

#include "rigger/dds/configuration.hpp"

namespace rigger::ctl {

/// Options shared by every command.
struct CommonOptions {
  std::uint32_t domain = 0;
};

/// `riggerctl services [--wait N] [--lost ID] [--timeout S]`: lists the rigger services alive on the
/// domain, or waits until N are READY, or until service ID is lost.
void add_services_command(CLI::App& app, const CommonOptions& common, int& exit_code);

/// `validate FILE [--library FILE]` (offline), `run FILE`, `status`, `tree TASK`, `skills`, `cancel TASK`,
/// `log TASK`. Exit codes: 0 ok; 1 invalid recipe / task not SUCCEEDED; 2 usage; 3 no task controller.
void add_task_commands(CLI::App& app, const CommonOptions& common, int& exit_code);

/// `operator [--list] [--answer PROMPT_ID=ANSWER]... [--timeout S]`: shows the pending operator prompts
/// and answers them (interactive on stdin by default). Exit codes: 0 ok; 1 prompt missing/withdrawn or
/// answer not an option; 2 usage.
void add_operator_command(CLI::App& app, const CommonOptions& common, int& exit_code);

/// `jog [--script STEPS | --device PATH | --keyboard] [--speed M/S] [--rate HZ]`: publishes the operator's
/// joystick reference (rigger/operator/joystick) and always ends with a zero twist. Exit codes: 0 ok;
/// 1 no reader (--script) or lost device; 2 usage.
void add_jog_command(CLI::App& app, const CommonOptions& common, int& exit_code);

/// `sim plc-link on|off`, `sim estop on|off`, `sim holding-force N|default`, `sim load-force FX FY FZ`,
/// `sim reset` [--timeout S]: fault injection into the simulated cell, answered by cell_sim. Exit
/// codes: 0 done; 1 refused or unanswered; 2 usage; 3 no simulator on the domain.
void add_sim_command(CLI::App& app, const CommonOptions& common, int& exit_code);

/// `estop [RESOURCE...] [--reset] [--reason TEXT]`: the software safe stop (rigger/safety/stop) of the
/// robot, crane, gripper and admittance controller (default: all), latched until `--reset`. Exit
/// codes: 0 acknowledged by the devices; 1 write failed or not acknowledged; 2 usage; 3 no device.
/// Who a command of this riggerctl is from: "riggerctl:<$USER>" (the uid without $USER), for the
/// issuer / source fields that the controller journals and the devices log.
std::string riggerctl_source();

void add_estop_command(CLI::App& app, const CommonOptions& common, int& exit_code);
/// `crane reset [--timeout S]`: CRANE_RESET to the crane gateway (acknowledges a latched PLC fault) and
/// waits until the crane reports no fault. Exit codes: 0 cleared; 1 still faulted (the cause is still
/// there); 2 usage; 3 no crane gateway.
void add_crane_command(CLI::App& app, const CommonOptions& common, int& exit_code);
/// `topics [--json] [--timeout S]`: every topic of the catalog with its type, QoS profile and the live
/// writers/readers (by service where known), plus topics seen on the wire outside the catalog.
/// `echo TOPIC [--count N] [--timeout S] [--duration S] [--json] [--hz]`: prints a topic's samples (or
/// their rate). Exit codes: 0 ok; 1 no writer within --timeout; 2 usage or unknown topic.
void add_topic_commands(CLI::App& app, const CommonOptions& common, int& exit_code);

/// `cell apply FILE [--comment T] [--dry-run]`, `cell show [REV]`, `cell history`, `cell diff A B`,
/// `cell rollback REV [--comment T]` [--json] [--timeout S]: the cell's revisions, kept by the world model
/// (docs/world-model.md). `who` is riggerctl_source(). Exit codes: 0 done; 1 refused (the code and the
/// world model's message are printed) or unanswered; 2 usage or an unreadable FILE; 3 no world model.
void add_cell_command(CLI::App& app, const CommonOptions& common, int& exit_code);

/// `calibrate camera [--camera ID] [--robot ID] [--poses N] [--tilt-deg D] [--shift-m M] [--max-residual-mm R]
/// [--max-residual-deg R] [--speed-scale S] [--timeout S] [--quiet]`: one run of the CalibrateCamera skill through
/// the task controller, followed like `run`. Exit codes as `run`'s: 0 calibrated (a new cell revision); 1 failed
/// (the skill's code and figures are printed; the cell is unchanged); 2 usage; 3 no task controller.
void add_calibrate_command(CLI::App& app, const CommonOptions& common, int& exit_code);

/// `cad inspect FILE [--json [--entities]]`, `cad frame FILE (--point X,Y,Z --edges E1,E2 | --face F
/// --point X,Y,Z | --hole H) [--json]`: offline STEP inspection (docs/cad.md). Exit codes: 0 ok; 1 the
/// file cannot be read or the picks make no frame (the CAD_* code is printed); 2 usage.
void add_cad_command(CLI::App& app, int& exit_code);

}  // namespace rigger::ctl
