// Reads a ROS 2 log with independent readers (npm: @mcap/core for .mcap, with CRC checks and
// @mcap/support's lz4 and zstd;
// @foxglove/rosbag2 + rosbag2-web for .db3) and prints JSON: each topic's type and message
// count, and the LaserScans of one topic (stamp, ranges; NaN as null, +Inf as "inf").
// usage: node read_ros2.js FILE SCAN_TOPIC   (NODE_PATH: the peers' node_modules)
"use strict";
const fs = require("fs");
const [file, scanTopic] = process.argv.slice(2);

function rangesOf(m) {
  return Array.from(m.ranges, (r) => (Number.isNaN(r) ? null : r === Infinity ? "inf" : r));
}

async function readMcap() {
  const { McapStreamReader } = require("@mcap/core");
  const { parse } = require("@foxglove/rosmsg");
  const { MessageReader } = require("@foxglove/rosmsg2-serialization");
  const { loadDecompressHandlers } = require("@mcap/support");  // lz4 and zstd chunks
  const reader = new McapStreamReader({ validateCrcs: true, decompressHandlers: await loadDecompressHandlers() });
  reader.append(new Uint8Array(fs.readFileSync(file)));
  const schemas = new Map(), channels = new Map(), topics = {}, scans = [];
  let done = false;
  for (let r; (r = reader.nextRecord()); ) {
    if (r.type === "Schema") schemas.set(r.id, r);
    else if (r.type === "Channel") {
      const s = schemas.get(r.schemaId);
      channels.set(r.id, { topic: r.topic, type: s.name, schema: s });
      topics[r.topic] = topics[r.topic] || { type: s.name, count: 0 };
    } else if (r.type === "Message") {
      const c = channels.get(r.channelId);
      topics[c.topic].count++;
      if (c.topic === scanTopic) {
        c.reader = c.reader || new MessageReader(parse(new TextDecoder().decode(c.schema.data), { ros2: true }));
        const m = c.reader.readMessage(r.data);
        scans.push({ sec: m.header.stamp.sec, nanosec: m.header.stamp.nanosec, ranges: rangesOf(m) });
      }
    } else if (r.type === "Footer") done = true;
  }
  if (!done || !reader.done()) throw new Error("no footer: the MCAP file is incomplete");
  // The summary, as a seeking reader (Foxglove's) uses it: chunk indexes, statistics.
  const { McapIndexedReader } = require("@mcap/core");
  const bytes = new Uint8Array(fs.readFileSync(file));
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers: await loadDecompressHandlers() });
  let indexedMessages = 0;
  for await (const m of indexed.readMessages()) indexedMessages += m ? 1 : 0;
  return { topics, scans, indexed: { messages: indexedMessages, statistics: Number(indexed.statistics?.messageCount ?? -1) } };
}

async function readDb3() {
  const { Rosbag2 } = require("@foxglove/rosbag2");
  const { SqliteSqljs } = require("@foxglove/rosbag2-web");
  // Node: hand sql.js its WebAssembly (it would fetch() a URL otherwise).
  const wasm = require.resolve("@foxglove/sql.js/dist/sql-wasm.wasm");
  await SqliteSqljs.Initialize({ wasmBinary: fs.readFileSync(wasm) });
  const bag = new Rosbag2([new SqliteSqljs(new Uint8Array(fs.readFileSync(file)))]);
  await bag.open();
  const topics = {};
  for (const t of await bag.readTopics()) topics[t.name] = { type: t.type, count: 0 };
  for (const [name, n] of await bag.messageCounts()) topics[name].count = n;
  const scans = [];
  for await (const m of bag.readMessages({ topics: [scanTopic] }))
    {
    const st = m.value.header.stamp;  // rosbag2's definitions name it nsec
    scans.push({ sec: st.sec, nanosec: st.nanosec ?? st.nsec, ranges: rangesOf(m.value) });
  }
  await bag.close();
  return { topics, scans };
}

(file.endsWith(".mcap") ? readMcap() : readDb3())
  .then((r) => process.stdout.write(JSON.stringify(r)))
  .catch((e) => {
    process.stderr.write(`read_ros2.js: ${file}: ${e.stack || e}\n`);
    process.exit(1);
  });
