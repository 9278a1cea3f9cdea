#include "deploy/synthesize.h"

#include <filesystem>
#include <fstream>

#include "deploy/json_writer.h"
#include "graph/export.h"
#include "version.h"

namespace eamos::deploy {

using nlohmann::json;

json manifest(const graph::Compilation& c, const std::string& hash) {
  json drones = json::array();
  for (int d = 0; d < c.drone_count(); ++d)
    drones.push_back({{"name", c.drone_name(d)},
                      {"type", c.settings[d].type},
                      {"adapter", c.settings[d].adapter},
                      {"folder", c.drone_name(d)},
                      {"mission", c.drone_name(d) + "/mission.json"}});
  return {{"format", "eamos-deployment"},
          {"format_version", kMissionFormatVersion},
          {"compiler", std::string("eamos ") + EAMOS_VERSION},
          {"mission_hash", hash},
          {"source", c.source->path},
          {"drones", drones}};
}

namespace {

nlohmann::ordered_json header_with(const graph::Compilation& c, const std::string& hash, double telemetry_hz,
                                   std::string source) {
  nlohmann::ordered_json drones = nlohmann::ordered_json::array();
  for (int d = 0; d < c.drone_count(); ++d) {
    const fleet::DroneSettings& s = c.settings[d];
    nlohmann::ordered_json reads = nlohmann::ordered_json::array();
    if (d < static_cast<int>(c.mdgs.size()))
      for (int r : c.mdgs[d].reads)
        if (r != d) reads.push_back(c.drone_name(r));
    drones.push_back({{"name", c.drone_name(d)},
                      {"index", d},
                      {"type", s.type},
                      {"adapter", s.adapter},
                      {"home", {s.home.x, s.home.y, s.home.z}},
                      {"reads", reads}});
  }
  nlohmann::ordered_json h;
  h["t"] = 0;
  h["event"] = "header";
  h["schema"] = "eamos-trace";
  h["version"] = kTraceSchemaVersion;
  h["eamos"] = EAMOS_VERSION;
  h["mission"] = std::filesystem::path(c.source->path).filename().string();
  h["mission_hash"] = hash;
  h["source"] = std::move(source);
  h["fleet"] = c.fleet.source ? c.fleet.source->text : "";
  h["drones"] = drones;
  h["telemetry_hz"] = telemetry_hz;
  return h;
}

}  // namespace

nlohmann::ordered_json trace_header(const graph::Compilation& c, const std::string& hash, double telemetry_hz) {
  return header_with(c, hash, telemetry_hz, c.source->text);
}

namespace {

bool cannot_write(const std::filesystem::path& path, Diagnostics& diags) {
  diags.error(nullptr, {}, "cannot write '" + path.string() + "'; check the output folder's permissions");
  return false;
}

bool write_text(const std::filesystem::path& path, const std::string& text, Diagnostics& diags) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  return out ? true : cannot_write(path, diags);
}

/// The header holds the mission's whole source: written as dump(2) would print it, but
/// the source's text is escaped by JsonWriter straight into the file's text, not copied
/// into the document and escaped by nlohmann's serializer (a tenth of a large show's
/// files stage; a copy of the source would be 35 MB of its peak). The two escape alike: quote,
/// backslash and control characters, as nlohmann does without ensure_ascii. A mission
/// that compiled is valid UTF-8 (the lexer reports any other byte), so nlohmann's
/// replacement of invalid bytes never applies to it; the fleet's text keeps nlohmann's.
bool write_trace_header(const graph::Compilation& c, const std::filesystem::path& path, const std::string& hash,
                        Diagnostics& diags) {
  std::string text = header_with(c, hash, 0, std::string()).dump(2, ' ', false, json::error_handler_t::replace);
  // The first "source" member is the header's own: a string value has its quotes escaped.
  const std::string_view empty_source = "\"source\": \"\"";
  std::size_t at = text.find(empty_source) + empty_source.size() - 2;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(at));
  {
    JsonWriter w(out);  // in pieces of 64 KB: the escaped source is never whole in memory
    w.value(c.source->text);
  }
  out.write(text.data() + at + 2, static_cast<std::streamsize>(text.size() - at - 2));
  out << '\n';
  out.close();
  return out ? true : cannot_write(path, diags);
}

}  // namespace

bool write_deployment(const graph::Compilation& c, const std::string& dir, Diagnostics& diags) {
  return write_deployment(c, dir, mission_hash(c), diags);
}

bool write_deployment(const graph::Compilation& c, const std::string& dir, const std::string& hash,
                      Diagnostics& diags) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    diags.error(nullptr, {}, "cannot create output folder '" + dir + "': " + ec.message());
    return false;
  }
  if (!write_text(fs::path(dir) / "manifest.json", manifest(c, hash).dump(2) + "\n", diags)) return false;
  if (!write_trace_header(c, fs::path(dir) / "trace-header.json", hash, diags)) return false;
  // One drone's file at a time is made in one buffer, reused (its capacity kept) by the next,
  // and written with one call: a large fleet's files are a third of the compile.
  std::string text;
  for (int d = 0; d < c.drone_count(); ++d) {
    fs::path folder = fs::path(dir) / c.drone_name(d);
    fs::create_directories(folder, ec);
    if (ec) {
      diags.error(nullptr, {}, "cannot create '" + folder.string() + "': " + ec.message());
      return false;
    }
    text.clear();
    append_drone_mission(text, c, d, hash);
    text += '\n';
    fs::path file = folder / "mission.json";
    if (!write_text(file, text, diags)) return false;
  }
  return true;
}

}  // namespace eamos::deploy
