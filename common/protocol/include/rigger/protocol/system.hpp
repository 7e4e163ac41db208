#pragma once
/// @file
/// The topics of system (idl/system.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::system {

/// every process → rigger-compose, tests, riggerctl.
inline constexpr Topic<rigger_system_ServiceState> kServiceState{
    "rigger/system/service_state",
    QosProfile::kAnnouncements,
    "service_id",
    "every process",
    "rigger-compose, tests, riggerctl",
    "",
    "readers use state(): they request no liveliness lease and see every announcer"};

/// echo → tests.
inline constexpr Topic<rigger_system_PeerView> kPeerView{
    "rigger/system/peer_view", QosProfile::kState, "observer_id", "echo", "tests", "", ""};

/// benchmark → echo.
inline constexpr Topic<rigger_system_EchoSample> kEchoRequest{"rigger/echo/request",
                                                              QosProfile::kSetpoints,
                                                              "client_id",
                                                              "benchmark",
                                                              "echo",
                                                              "",
                                                              "reliable, keep-last 1, as ddsperf"};

/// echo → benchmark.
inline constexpr Topic<rigger_system_EchoSample> kEchoReply{"rigger/echo/reply",
                                                            QosProfile::kSetpoints,
                                                            "client_id",
                                                            "echo",
                                                            "benchmark",
                                                            "",
                                                            "reliable, keep-last 1, as ddsperf"};

}  // namespace rigger::protocol::system
