#!/usr/bin/env node
// The independent side of the MAVLink cross-check: node-mavlink shares no code and no reading
// of the specification with src/mavlink, so a frame both accept and decode alike is a frame
// PX4, ArduPilot and QGroundControl will too. Driven by tests/mavlink/node_crosscheck_test.cpp
// and tests/mavlink_adapter/node_capture_test.cpp; usable by hand as well:
//
//   node mavlink_node.js decode [FILE]     raw bytes (FILE, else stdin) -> one JSON line per frame,
//                                          then {"summary": {frames, crc_errors, unknown}}
//   node mavlink_node.js encode SPEC OUT   JSON lines {msgid, sysid, compid, seq, fields} -> frames
//   node mavlink_node.js describe ID...    node-mavlink's table entry (CRC_EXTRA, length, offsets)
//
// Field names are common.xml's (node-mavlink's `source`), not its camelCase property names,
// so they compare directly with src/mavlink/messages.cpp. Values JSON cannot hold are strings:
// 64-bit integers (exact decimal) and non-finite floats ("NaN", "Infinity", "-Infinity").
'use strict'

const fs = require('node:fs')
const {
  MavLinkPacketSplitter, MavLinkPacketParser, MavLinkProtocolV2, minimal, common, ardupilotmega,
} = require('node-mavlink')

// ardupilotmega for CAMERA_FEEDBACK (180), which ArduPilot sends for a picture taken.
const REGISTRY = { ...minimal.REGISTRY, ...common.REGISTRY, ...ardupilotmega.REGISTRY }

function toJson(value) {
  if (typeof value === 'bigint') return value.toString()
  if (typeof value === 'number' && !Number.isFinite(value)) return String(value)
  if (Array.isArray(value)) return value.map(toJson)
  return value
}

function fromJson(value, type) {
  if (Array.isArray(value)) return value.map(v => fromJson(v, type.replace('[]', '')))
  if (type.startsWith('uint64_t') || type.startsWith('int64_t')) return BigInt(value)
  if (typeof value === 'string' && (type.startsWith('float') || type.startsWith('double'))) {
    return Number(value)  // "NaN", "Infinity", "-Infinity"
  }
  return value
}

function decode(file) {
  const bytes = fs.readFileSync(file === undefined ? 0 : file)
  const splitter = new MavLinkPacketSplitter()
  const parser = splitter.pipe(new MavLinkPacketParser())
  let frames = 0
  parser.on('data', packet => {
    frames++
    const h = packet.header
    const clazz = REGISTRY[h.msgid]
    const line = {
      msgid: h.msgid, name: clazz ? clazz.MSG_NAME : null, sysid: h.sysid, compid: h.compid,
      seq: h.seq, len: h.payloadLength, incompat_flags: h.incompatibilityFlags, fields: {},
    }
    if (clazz) {
      const data = packet.protocol.data(packet.payload, clazz)
      for (const f of clazz.FIELDS) line.fields[f.source] = toJson(data[f.name])
    }
    process.stdout.write(JSON.stringify(line) + '\n')
  })
  parser.on('end', () => {
    const summary = {
      frames, crc_errors: splitter.invalidPackages, unknown: splitter.unknownPackagesCount,
    }
    process.stdout.write(JSON.stringify({ summary }) + '\n')
  })
  splitter.end(bytes)
}

function encode(specFile, outFile) {
  const frames = []
  const lines = fs.readFileSync(specFile, 'utf8').split('\n').filter(l => l.trim() !== '')
  for (const text of lines) {
    const spec = JSON.parse(text)
    const clazz = REGISTRY[spec.msgid]
    if (!clazz) throw new Error(`node-mavlink does not know message id ${spec.msgid}`)
    const message = new clazz()
    // Every field starts at zero, not at node-mavlink's defaults (first enum value, etc.),
    // so a field the spec leaves out is zero on both sides.
    for (const f of clazz.FIELDS) {
      message[f.name] = fromJson(f.length ? new Array(f.length).fill(0) : 0, f.type)
    }
    const known = new Set(clazz.FIELDS.map(f => f.source))
    for (const [name, value] of Object.entries(spec.fields || {})) {
      // A misspelt name would otherwise be sent as zero and the test would compare zeros.
      if (!known.has(name)) throw new Error(`${clazz.MSG_NAME} has no field ${name}`)
      const f = clazz.FIELDS.find(x => x.source === name)
      message[f.name] = fromJson(value, f.type)
    }
    const protocol = new MavLinkProtocolV2(spec.sysid, spec.compid)
    frames.push(protocol.serialize(message, spec.seq))
  }
  fs.writeFileSync(outFile, Buffer.concat(frames))
}

function describe(ids) {
  for (const id of ids) {
    const clazz = REGISTRY[Number(id)]
    if (!clazz) throw new Error(`node-mavlink does not know message id ${id}`)
    const fields = clazz.FIELDS.map(f => ({
      name: f.source, type: f.type, offset: f.offset, extension: f.extension, length: f.length,
    }))
    process.stdout.write(JSON.stringify({
      msgid: clazz.MSG_ID, name: clazz.MSG_NAME, crc_extra: clazz.MAGIC_NUMBER,
      length: clazz.PAYLOAD_LENGTH, fields,
    }) + '\n')
  }
}

const [command, ...args] = process.argv.slice(2)
try {
  if (command === 'decode') decode(args[0])
  else if (command === 'encode' && args.length === 2) encode(args[0], args[1])
  else if (command === 'describe') describe(args)
  else throw new Error('usage: mavlink_node.js decode [FILE] | encode SPEC OUT | describe ID...')
} catch (e) {
  process.stderr.write(`mavlink_node.js: ${e.message}\n`)
  process.exit(2)
}
