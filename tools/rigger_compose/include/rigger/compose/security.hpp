#pragma once
/// @file
/// `rigger-compose --secure`: DDS Security for every service and for rigger-compose itself
/// (docs/security.md). The PKI is made by deploy/security/make-pki; the secured Cyclone configuration
/// (deploy/cyclonedds-secure.xml) takes the PKI folder and the identity from the environment.

#include <stdexcept>
#include <string>

#include "rigger/compose/compose_file.hpp"

namespace rigger::compose {

/// The PKI folder: $RIGGER_SECURITY_DIR, else /var/tmp/rigger/security (make-pki's default).
std::string default_security_dir();

/// The identities a secured cell needs: one per service (RIGGER_IDENTITY in its env:, else its name).
/// Points `file` at the secured configuration ($RIGGER_SECURE_DDS_CONFIG, else
/// <root>/deploy/cyclonedds-secure.xml), adds RIGGER_IDENTITY and RIGGER_SECURITY_DIR to every service's
/// environment, and sets RIGGER_SECURITY_DIR (and RIGGER_IDENTITY=rigger-compose unless set) for this
/// process, whose own participant joins the secured domain too.
/// @throws std::runtime_error naming everything that is missing (PKI folder, CA, identities: one line
///         each) and the command that makes it; nothing is changed then.
void apply_security(ComposeFile& file, const std::string& security_dir);

/// The identity a tool started by rigger-compose runs as (riggerctl for `demo`).
inline constexpr const char* kRiggerctlIdentity = "riggerctl";

}  // namespace rigger::compose
