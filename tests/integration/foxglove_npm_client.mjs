// A viewer as Foxglove's own libraries make one, for tests/integration/test_live_view_npm.py:
//   node foxglove_npm_client.mjs URL MODULES_DIR SECONDS
// The official client @foxglove/ws-protocol (FoxgloveClient, over the `ws` package, offering the
// protocol's subprotocol as that client names it) connects to URL (retrying while the server is
// not up yet), subscribes every channel in the same turn as its advertisement (as Foxglove
// does), and decodes every message with the advertised schema alone: ros2msg + cdr with
// @foxglove/rosmsg and @foxglove/rosmsg2-serialization (what Foxglove uses), protobuf with
// protobufjs from the advertised FileDescriptorSet, json with JSON.parse. MODULES_DIR holds the
// packages (foxglove_npm/package.json, installed by the test). Prints JSON lines: "open" (with
// the wall time, s), "advertise" (one per channel), "status" (the server's), "first" (the
// first message of each channel, decoded), "refused", and at the end one "channel" line per
// channel (messages, decode errors, log times going backwards, first and last log time) and
// "end". Ends after SECONDS, when the server closes, or on SIGTERM.
import { createRequire } from "node:module";
import path from "node:path";

const [url, modulesDir, secondsArg] = process.argv.slice(2);
const require = createRequire(path.join(path.resolve(modulesDir), "package.json"));
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parse: parseRosMsg } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const protobuf = require("protobufjs");
const descriptor = require("protobufjs/ext/descriptor");
const WebSocket = require("ws");

const seconds = Number(secondsArg ?? 60);
const started = Date.now();
const channels = new Map(); // channel id -> state
const bySubscription = new Map(); // subscription id -> state
let finished = false;

function out(obj) {
  process.stdout.write(JSON.stringify(obj, (k, v) => (typeof v === "bigint" ? Number(v) : v)) + "\n");
}

function plain(value, depth = 0) {
  // A decoded message as JSON: typed arrays shortened, bigints as numbers, Long as numbers.
  if (value === null || value === undefined) return value;
  if (typeof value === "bigint") return Number(value);
  if (ArrayBuffer.isView(value)) return { length: value.length };
  if (Array.isArray(value)) return depth > 3 ? { length: value.length } : value.slice(0, 3).map((v) => plain(v, depth + 1));
  if (typeof value === "object") {
    if (typeof value.toNumber === "function") return value.toNumber();
    const o = {};
    for (const [k, v] of Object.entries(value)) o[k] = plain(v, depth + 1);
    return o;
  }
  return value;
}

function decoderFor(ch) {
  if (ch.encoding === "cdr" && ch.schemaEncoding === "ros2msg") {
    const reader = new MessageReader(parseRosMsg(ch.schema, { ros2: true }));
    return (bytes) => reader.readMessage(bytes);
  }
  if (ch.encoding === "protobuf") {
    const set = descriptor.FileDescriptorSet.decode(Buffer.from(ch.schema, "base64"));
    const type = protobuf.Root.fromDescriptor(set).lookupType(ch.schemaName);
    return (bytes) => type.toObject(type.decode(bytes), { longs: Number, defaults: true });
  }
  if (ch.encoding === "json") {
    const text = new TextDecoder();
    return (bytes) => JSON.parse(text.decode(bytes));
  }
  throw new Error(`no decoder for encoding ${ch.encoding} / schema ${ch.schemaEncoding}`);
}

function finish(reason) {
  if (finished) return;
  finished = true;
  for (const s of channels.values()) {
    out({ event: "channel", topic: s.topic, id: s.id, schemaName: s.schemaName, encoding: s.encoding,
      messages: s.messages, decodeErrors: s.decodeErrors, firstError: s.firstError,
      backwards: s.backwards, firstLogTime: s.firstLogTime, lastLogTime: s.lastLogTime });
  }
  out({ event: "end", reason, seconds: (Date.now() - started) / 1000 });
  process.exit(0);
}

function connect() {
  if (finished) return;
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  let opened = false;
  ws.on("unexpected-response", (_req, res) => {
    out({ event: "refused", status: res.statusCode, subprotocol: FoxgloveClient.SUPPORTED_SUBPROTOCOL });
    finished = true;
    process.exit(3);
  });
  ws.on("error", (err) => {
    if (!opened && (err.code === "ECONNREFUSED" || err.code === "ECONNRESET")) {
      setTimeout(connect, 200);
    } else if (opened) {
      out({ event: "error", message: String(err.message ?? err) });
    }
  });
  ws.on("open", () => {
    opened = true;
    out({ event: "open", subprotocol: ws.protocol, wallTime: Date.now() / 1000 });
    const client = new FoxgloveClient({ ws });
    client.on("serverInfo", (info) => out({ event: "serverInfo", name: info.name, capabilities: info.capabilities }));
    client.on("status", (s) => out({ event: "status", level: s.level, message: s.message }));
    client.on("advertise", (list) => {
      for (const ch of list) {
        const s = { id: ch.id, topic: ch.topic, schemaName: ch.schemaName, encoding: ch.encoding,
          messages: 0, decodeErrors: 0, firstError: null, backwards: 0, firstLogTime: null, lastLogTime: null };
        try {
          s.decode = decoderFor(ch);
        } catch (err) {
          s.decode = () => { throw err; };
        }
        channels.set(ch.id, s);
        bySubscription.set(client.subscribe(ch.id), s); // at once, as Foxglove does
        out({ event: "advertise", topic: ch.topic, id: ch.id, schemaName: ch.schemaName,
          encoding: ch.encoding, schemaEncoding: ch.schemaEncoding });
      }
    });
    client.on("message", ({ subscriptionId, timestamp, data }) => {
      const s = bySubscription.get(subscriptionId);
      if (!s) return;
      const t = Number(timestamp);
      const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
      let msg = null;
      try {
        msg = s.decode(bytes);
      } catch (err) {
        s.decodeErrors += 1;
        s.firstError ??= String(err.message ?? err);
      }
      if (s.lastLogTime !== null && t < s.lastLogTime) s.backwards += 1;
      if (s.messages === 0) {
        s.firstLogTime = t;
        out({ event: "first", topic: s.topic, logTime: t, message: msg === null ? null : plain(msg) });
      }
      s.messages += 1;
      s.lastLogTime = t;
    });
    client.on("close", () => finish("closed"));
  });
}

process.on("SIGTERM", () => finish("SIGTERM"));
process.on("SIGINT", () => finish("SIGINT"));
setTimeout(() => finish("time"), seconds * 1000);
connect();
