#!/usr/bin/env node
// A standalone ROS 2 implementation, @foxglove/ros2 (TypeScript RTPS, no DDS library, no ROS 2),
// subscribing to a topic rigger's ros2_bridge publishes: the live half of docs/ros2.md's proof. It
// discovers the bridge, matches its writer on type name and QoS, receives the samples and decodes them
// with @foxglove/rosmsg2-serialization from @foxglove/rosmsg-msgs-common's ROS 2 definitions.
//
//   node live_subscriber.js --domain 42 --topic /servo_node/delta_twist_cmds \
//        --type geometry_msgs/msg/TwistStamped --count 100 [--reliability reliable|best_effort]
//        [--participant-index 99] [--address 127.0.0.1] [--timeout-s 60] [--verbose] [--as-is]
//
// --address is the IPv4 address of the interface it announces to its peers (on loopback 127.0.0.1; in a
// lab host, its eth0 address: there discovery is by multicast on eth0, deploy/cyclonedds-lab.xml).
//
// Prints one JSON line per event on stdout: {"event":"started",...}, {"event":"publisher",...} when a
// matching writer is discovered, {"event":"sample","recv_ns":…,"msg":{…}} per sample, and
// {"event":"done","received":N,...} when N >= --count (exit 0), or {"event":"timeout"} (exit 1).
//
// Two adaptations, both outside @foxglove/ros2's own code, and said here so nobody takes them for its
// defaults:
//  - Reader QoS. @foxglove/ros2 1.0.8's RosNode.subscribe() always asks for RELIABLE, TRANSIENT_LOCAL,
//    keep-last 1. A DDS writer with VOLATILE durability (every ROS 2 profile rigger uses, and what
//    rclcpp gives by default) must not match a TRANSIENT_LOCAL reader, and Cyclone does not: such a
//    subscription receives nothing. So the subscription is made as RosNode.subscribe() makes it, with
//    the same Subscription class, but with VOLATILE durability and the reliability the topic is
//    published with (ROS 2's own readers are volatile by default too).
//  - Discovery without multicast. rigger's Cyclone configuration (deploy/cyclonedds.xml) is
//    loopback-only with multicast off: participants find each other by unicast SPDP to the well-known
//    ports of participant indices 0..100 on 127.0.0.1. @foxglove/rtps binds its unicast socket to a
//    random port and announces itself by multicast only, so the two would never meet. The UDP socket
//    factory (the transport layer @foxglove/rtps takes as a plug-in) binds that socket to the well-known
//    port of participant index --participant-index instead, where Cyclone's SPDP reaches it; the RTPS
//    code then answers Cyclone's SPDP by unicast on its own. A failed multicast join (a namespace
//    whose only interface is lo) is ignored for the same reason.
"use strict";

function arg(name, fallback) {
  const i = process.argv.indexOf(`--${name}`);
  if (i < 0) {
    if (fallback === undefined) throw new Error(`missing --${name}`);
    return fallback;
  }
  return process.argv[i + 1];
}

let ros2, rtps, rtpsNode, definitions;
try {
  ros2 = require("@foxglove/ros2");
  rtps = require("@foxglove/rtps");
  rtpsNode = require("@foxglove/rtps/nodejs");
  definitions = require("@foxglove/rosmsg-msgs-common").ros2humble;
} catch (e) {
  console.error(`live_subscriber: ${e.message}\nrun 'npm ci' in test/ros2 (deploy/setup does)`);
  process.exit(2);
}

const domainId = Number(arg("domain"));
const topic = arg("topic");
const dataType = arg("type");
const count = Number(arg("count", "100"));
const reliable = arg("reliability", "reliable") === "reliable";
const participantIndex = Number(arg("participant-index", "99"));
const address = arg("address", "127.0.0.1");
const timeoutMs = 1000 * Number(arg("timeout-s", "60"));

function emit(obj) {
  process.stdout.write(JSON.stringify(obj, (_k, v) => (typeof v === "bigint" ? v.toString() : v)) + "\n");
}

// The transport plug-in (see above): the participant's one unicast socket on a well-known port.
let unicastBound = false;
async function udpSocketCreate(options) {
  const socket = await rtpsNode.UdpSocketNode.Create(options);
  const bind = socket.bind.bind(socket);
  socket.bind = async (opts) => {
    if (opts.port === undefined && !unicastBound) {
      unicastBound = true;
      return bind({ ...opts, port: rtps.discoveryUnicastPort(domainId, participantIndex) });
    }
    return bind(opts);
  };
  const addMembership = socket.addMembership.bind(socket);
  socket.addMembership = async (...a) => {
    try {
      await addMembership(...a);
    } catch (e) {
      emit({ event: "no_multicast", error: String(e) });
    }
  };
  return socket;
}

async function main() {
  const key = dataType.replace("/msg/", "/");
  if (!(key in definitions)) throw new Error(`no ROS 2 definition for ${dataType}`);
  const msgDefinition = [definitions[key], ...Object.values(definitions)];

  const node = new ros2.RosNode({
    name: "rigger_live_subscriber",
    domainId,
    addresses: [address],
    udpSocketCreate,
    log: process.argv.includes("--verbose") ? console : undefined,
  });
  node.on("discoveredPublication", (p) => {
    if (p.topicName === ros2.rosTopicToDds(topic)) {
      emit({ event: "publisher", topic: p.topicName, type: p.typeName, reliability: p.reliability.kind });
    }
  });
  await node.start();

  // --as-is: RosNode.subscribe() unchanged (RELIABLE, TRANSIENT_LOCAL), to show it receives nothing
  // from a VOLATILE writer.
  let sub;
  if (process.argv.includes("--as-is")) {
    sub = node.subscribe({ topic, dataType, msgDefinition });
  }
  // As RosNode.subscribe() does it, but VOLATILE (see the header).
  const participant = node._participant;
  const subscribeOpts = {
    topicName: ros2.rosTopicToDds(topic),
    typeName: ros2.rosTypeToDds(dataType),
    durability: rtps.Durability.Volatile,
    reliability: reliable
      ? { kind: rtps.Reliability.Reliable, maxBlockingTime: { sec: 0x7fffffff, nsec: 0xffffffff } }
      : { kind: rtps.Reliability.BestEffort, maxBlockingTime: { sec: 0, nsec: 0 } },
    history: { kind: rtps.HistoryKind.KeepLast, depth: 10 },
  };
  if (sub === undefined) {
    const readerEntityId = participant.subscribe(subscribeOpts);
    sub = new ros2.Subscription({ subscribeOpts, readerEntityId, participant, msgDefinition });
  }
  emit({ event: "started", domain: domainId, dds_topic: subscribeOpts.topicName, type: subscribeOpts.typeName,
         reliable, as_is: process.argv.includes("--as-is"), address,
         port: rtps.discoveryUnicastPort(domainId, participantIndex) });

  let received = 0;
  let firstNs = 0n;
  let lastNs = 0n;
  const finish = async (code, event) => {
    emit(event);
    clearTimeout(timer);
    await node.shutdown();
    process.exit(code);
  };
  const timer = setTimeout(() => void finish(1, { event: "timeout", received }), timeoutMs);
  process.on("SIGINT", () => void finish(130, { event: "interrupted", received }));

  sub.on("message", (_timestamp, msg) => {
    const now = process.hrtime.bigint();
    if (received === 0) firstNs = now;
    lastNs = now;
    received += 1;
    emit({ event: "sample", recv_ns: now, msg });
    if (received >= count) {
      const seconds = Number(lastNs - firstNs) / 1e9;
      void finish(0, { event: "done", received, seconds, rate_hz: seconds > 0 ? (received - 1) / seconds : 0 });
    }
  });
}

main().catch((e) => {
  console.error(`live_subscriber: ${e.stack || e}`);
  process.exit(1);
});
