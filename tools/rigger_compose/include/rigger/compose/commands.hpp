#pragma once
/// @file
/// The rigger-compose command line:
///
///   rigger-compose [--file F] [--domain D] [--host H] up [SERVICE…]   start (in the background), wait for READY
///   rigger-compose … down                                             stop everything, wait for it
///   rigger-compose … ps [--json]                                      supervisor state merged with DDS state
///   rigger-compose … logs SERVICE [-f] [-n N]                         a service's log (or "supervisor")
///   rigger-compose … restart SERVICE                                  restart one service, wait for READY
///   rigger-compose … demo [--recipe R]                                up, riggerctl run R, down
///   rigger-compose … config                                           validate and show the resolved file
///
/// `--secure` (before or after the command, e.g. `up --secure`, `demo --secure`, `ps --secure`): DDS
/// Security, the PKI of deploy/security/make-pki (security.hpp, docs/security.md).
///
/// Exit codes: 0 success; 1 failure (a service did not come up, nothing to stop…); 2 bad command line
/// or compose file.

namespace rigger::compose {

/// Parses the command line and runs the command. Returns the exit code; never throws.
int run_cli(int argc, char** argv);

}  // namespace rigger::compose
