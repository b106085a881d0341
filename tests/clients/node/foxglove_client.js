// The Foxglove WebSocket protocol's own client (@foxglove/ws-protocol 0.8.0, subprotocol
// foxglove.websocket.v1, what Lichtblick speaks) against `roam view`: connects, waits
// for the channel TOPIC, subscribes, and prints one JSON line with the subprotocol the
// server chose, the channel and the first message's bytes in hex. With NEEDLEs, it
// keeps receiving until every NEEDLE (an entity id such as `estimate/r1`) has appeared
// in some message on the channel, and prints the first message instead with `seen`.
// Exit code 1 on any failure or after 60 s.
//
//   node foxglove_client.js ws://127.0.0.1:8765 /map/occupancy
//   node foxglove_client.js ws://127.0.0.1:8765 /robots/estimate estimate/r1 estimate/r2
"use strict";

const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");

const [url, topic, ...needles] = process.argv.slice(2);
const missing = new Set(needles);
let first;
if (!url || !topic) {
  console.error("usage: node foxglove_client.js URL TOPIC");
  process.exit(2);
}

const timer = setTimeout(() => {
  console.error(`no message on ${topic} within 60 s` + (missing.size ? ` naming ${[...missing].join(", ")}` : ""));
  process.exit(1);
}, 60000);

const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
let channel;
let serverName;

client.on("error", (error) => {
  console.error(`error: ${error}`);
  process.exit(1);
});
client.on("serverInfo", (info) => {
  serverName = info.name;
});
client.on("advertise", (channels) => {
  if (channel) return;
  channel = channels.find((c) => c.topic === topic);
  if (channel) client.subscribe(channel.id);
});
client.on("message", (event) => {
  const bytes = Buffer.from(event.data.buffer, event.data.byteOffset, event.data.byteLength);
  first = first || bytes;
  const text = bytes.toString("latin1");
  for (const needle of [...missing]) {
    if (text.includes(needle)) missing.delete(needle);
  }
  if (missing.size > 0) return;
  clearTimeout(timer);
  console.log(
    JSON.stringify({
      subprotocol: ws.protocol,
      server: serverName,
      topic: channel.topic,
      encoding: channel.encoding,
      schemaName: channel.schemaName,
      data_hex: first.toString("hex"),
      seen: needles,
    }),
  );
  client.close();
  process.exit(0);
});
