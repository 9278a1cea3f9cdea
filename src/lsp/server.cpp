#include "lsp/server.h"

#include <unistd.h>

#include <algorithm>
#include <climits>
#include <csignal>
#include <filesystem>
#include <new>

#include "lsp/features.h"
#include "lsp/framing.h"
#include "version.h"

namespace eamos::lsp {

using nlohmann::json;

namespace {

// JSON-RPC 2.0 and LSP error codes.
constexpr int kParseError = -32700, kInvalidRequest = -32600, kMethodNotFound = -32601, kInvalidParams = -32602,
              kInternalError = -32603, kServerNotInitialized = -32002;

// No LSP message nests deeper than a dozen levels; a JSON value copied or freed recursively
// could exhaust the stack at a few hundred thousand, so deeper input is refused unparsed.
constexpr int kMaxNesting = 256;

// The deepest nesting of arrays and objects in JSON text (brackets inside strings do not count).
int nesting_depth(const std::string& text) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// A request's params that are not what the protocol says: answered with InvalidParams.
struct BadParams {
  std::string message;
};

const json& member(const json& j, const std::string& key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw BadParams{where + "." + key + " is missing"};
  return j[key];
}

std::string string_at(const json& j, const std::string& key, const std::string& where) {
  const json& v = member(j, key, where);
  if (!v.is_string()) throw BadParams{where + "." + key + " must be a string"};
  return v.get<std::string>();
}

int count_at(const json& j, const std::string& key, const std::string& where) {
  const json& v = member(j, key, where);
  if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > INT_MAX)
    throw BadParams{where + "." + key + " must be a whole number from 0 to " + std::to_string(INT_MAX)};
  return static_cast<int>(v.get<long long>());
}

Position position_at(const json& j, const std::string& key, const std::string& where) {
  const json& p = member(j, key, where);
  return {count_at(p, "line", where + "." + key), count_at(p, "character", where + "." + key)};
}

// The member at a path of keys; null when a step is missing or not an object.
const json* at_path(const json& j, std::initializer_list<const char*> keys) {
  const json* at = &j;
  for (const char* k : keys) {
    if (!at->is_object() || !at->contains(k)) return nullptr;
    at = &(*at)[k];
  }
  return at;
}

std::string uri_of(const json& params) {
  return string_at(member(params, "textDocument", "params"), "uri", "params.textDocument");
}

// The byte offset of a protocol position in `file` (clamped to its end).
std::size_t offset_of(const SourceFile& file, Position p, Encoding enc) {
  if (static_cast<std::size_t>(p.line) >= file.line_starts.size()) return file.text.size();
  return file.line_starts[p.line] + bytes_for(file.line(p.line + 1), p.character, enc);
}

// An absolute path for a fleet file named relative to `base` (the workspace folder, or the
// server's working directory as for `eamos check --fleet`).
std::string absolute_fleet(const std::string& path, const std::string& base) {
  if (path.empty()) return "";
  std::filesystem::path p(path);
  if (p.is_relative() && !base.empty()) p = std::filesystem::path(base) / p;
  std::error_code ec;
  std::filesystem::path abs = std::filesystem::absolute(p, ec);
  return (ec ? p : abs).lexically_normal().string();
}

std::string workspace_folder(const json& params) {
  if (params.contains("rootUri") && params["rootUri"].is_string())
    return uri_to_path(params["rootUri"].get<std::string>());
  if (params.contains("rootPath") && params["rootPath"].is_string()) return params["rootPath"].get<std::string>();
  return "";
}

}  // namespace

void Server::reply(const json& id, json result) {
  outbox_.push_back({{"jsonrpc", "2.0"}, {"id", id}, {"result", std::move(result)}});
}

void Server::reply_error(const json& id, int code, const std::string& message) {
  outbox_.push_back({{"jsonrpc", "2.0"}, {"id", id}, {"error", {{"code", code}, {"message", message}}}});
}

json Server::framing_error(const std::string& reason) const {
  return {{"jsonrpc", "2.0"},
          {"id", nullptr},
          {"error",
           {{"code", kParseError},
            {"message", "cannot read a message: " + reason +
                            "; each message is a 'Content-Length: N' header, a blank line and N bytes of JSON"}}}};
}

std::optional<int> Server::dispatch(const std::string& body) {
  if (nesting_depth(body) > kMaxNesting) {
    reply_error(nullptr, kInvalidRequest,
                "the message nests arrays and objects deeper than " + std::to_string(kMaxNesting) + " levels");
    return {};
  }
  json msg = json::parse(body, nullptr, false);
  if (msg.is_discarded()) {
    reply_error(nullptr, kParseError, "the message is not valid JSON; send one JSON-RPC object per frame");
    return {};
  }
  if (!msg.is_object()) {
    reply_error(nullptr, kInvalidRequest, "a message must be a JSON object (LSP has no batches)");
    return {};
  }
  bool has_id = msg.contains("id");
  json id = has_id ? msg["id"] : json();
  if (has_id && !id.is_number_integer() && !id.is_string()) {
    reply_error(nullptr, kInvalidRequest, "the id must be an integer or a string");
    return {};
  }
  if (!takes(msg, id, has_id)) return {};
  std::string method = msg["method"].get<std::string>();
  // JSON-RPC leaves params out when there are none; some clients send null instead (shutdown).
  json params = msg.contains("params") && !msg["params"].is_null() ? msg["params"] : json::object();
  if (!params.is_object() && !params.is_array()) {
    reply_error(id, kInvalidRequest, "\"params\" must be an object or an array");
    return {};
  }
  if (method == "exit") return shutting_down_ ? 0 : 1;
  try {
    if (has_id)
      request(id, method, params);
    else
      notification(method, params);
  } catch (const BadParams& e) {
    if (has_id)
      reply_error(id, kInvalidParams, "invalid params of " + method + ": " + e.message);
    else
      outbox_.push_back({{"jsonrpc", "2.0"},
                         {"method", "window/logMessage"},
                         {"params", {{"type", 1}, {"message", "eamos lsp: ignored " + method + ": " + e.message}}}});
  } catch (const std::exception&) {
    // A bug of the server, never of the input: say so, and keep serving.
    if (has_id) reply_error(id, kInternalError, "eamos lsp failed on " + method + "; please report it with the file");
  }
  return {};
}

bool Server::takes(const json& msg, const json& id, bool has_id) {
  if (!msg.contains("jsonrpc") || msg["jsonrpc"] != "2.0") {
    reply_error(id, kInvalidRequest, "\"jsonrpc\" must be \"2.0\"");
    return false;
  }
  if (!msg.contains("method")) {
    // A response to a request of ours: this server sends none, so there is nothing to match.
    if (has_id && (msg.contains("result") || msg.contains("error"))) return false;
    reply_error(id, kInvalidRequest, "no \"method\": a request or notification must name one");
    return false;
  }
  if (!msg["method"].is_string()) {
    reply_error(id, kInvalidRequest, "\"method\" must be a string");
    return false;
  }
  return true;
}

void Server::request(const json& id, const std::string& method, const json& params) {
  if (method == "initialize") {
    if (initialized_) return reply_error(id, kInvalidRequest, "initialize was already received");
    return reply(id, initialize(params));
  }
  if (!initialized_)
    return reply_error(id, kServerNotInitialized, "the server is not initialized; send initialize first");
  if (shutting_down_) return reply_error(id, kInvalidRequest, "the server is shutting down; only exit is accepted");
  if (method == "shutdown") {
    shutting_down_ = true;
    return reply(id, nullptr);
  }
  if (method == "textDocument/hover" || method == "textDocument/definition" || method == "textDocument/completion" ||
      method == "textDocument/documentSymbol")
    return reply(id, document_request(method, params));
  reply_error(id, kMethodNotFound, "eamos lsp does not implement " + method);
}

void Server::notification(const std::string& method, const json& params) {
  // Before initialize and after shutdown, notifications are dropped (LSP 3.17).
  if (!initialized_ || shutting_down_) return;
  if (method == "textDocument/didOpen")
    open(params);
  else if (method == "textDocument/didChange")
    change(params);
  else if (method == "textDocument/didClose")
    close(params);
}

json Server::initialize(const json& params) {
  if (!params.is_object()) throw BadParams{"params must be an object"};
  // The compiler counts bytes: take UTF-8 when the client offers it, else LSP's UTF-16.
  const json* encodings = at_path(params, {"capabilities", "general", "positionEncodings"});
  if (encodings && encodings->is_array())
    for (const auto& e : *encodings)
      if (e == "utf-8") encoding_ = Encoding::utf8;
  const json* hierarchical =
      at_path(params, {"capabilities", "textDocument", "documentSymbol", "hierarchicalDocumentSymbolSupport"});
  hierarchical_symbols_ = hierarchical && *hierarchical == true;
  const json* related =
      at_path(params, {"capabilities", "textDocument", "publishDiagnostics", "relatedInformation"});
  related_information_ = related && *related == true;

  fleet_path_ = absolute_fleet(options_.fleet, "");
  if (const json* options = at_path(params, {"initializationOptions"}); options && at_path(*options, {"fleet"}))
    fleet_path_ =
        absolute_fleet(string_at(*options, "fleet", "params.initializationOptions"), workspace_folder(params));
  initialized_ = true;
  json capabilities = {
      {"positionEncoding", encoding_ == Encoding::utf8 ? "utf-8" : "utf-16"},
      {"textDocumentSync", {{"openClose", true}, {"change", 1}}},  // 1: the whole text each time
      {"hoverProvider", true},
      {"definitionProvider", true},
      {"completionProvider", {{"triggerCharacters", {"."}}}},
      {"documentSymbolProvider", true},
  };
  return {{"capabilities", capabilities}, {"serverInfo", {{"name", "eamos"}, {"version", EAMOS_VERSION}}}};
}

json Server::document_request(const std::string& method, const json& params) {
  std::string uri = uri_of(params);
  auto it = documents_.find(uri);
  if (it == documents_.end()) throw BadParams{uri + " is not open; send textDocument/didOpen first"};
  const Document& doc = it->second;
  if (method == "textDocument/documentSymbol") return document_symbols(doc, encoding_, hierarchical_symbols_);
  Position at = position_at(params, "position", "params");
  if (method == "textDocument/hover") return hover(doc, fleet_, at, encoding_);
  if (method == "textDocument/definition") return definition(doc, at, encoding_);
  return completion(doc, fleet_, at, encoding_);
}

void Server::open(const json& params) {
  const json& item = member(params, "textDocument", "params");
  std::string uri = string_at(item, "uri", "params.textDocument");
  std::string text = string_at(item, "text", "params.textDocument");
  const json& version = member(item, "version", "params.textDocument");
  if (!version.is_number_integer()) throw BadParams{"params.textDocument.version must be an integer"};
  Document& doc = documents_[uri];
  doc.uri = uri;
  doc.path = uri_to_path(uri);
  if (doc.path.empty()) doc.path = uri;
  doc.version = version.get<long long>();
  check(doc, std::move(text));
}

void Server::change(const json& params) {
  std::string uri = uri_of(params);
  auto it = documents_.find(uri);
  if (it == documents_.end()) throw BadParams{uri + " is not open; send textDocument/didOpen first"};
  const json& version = member(member(params, "textDocument", "params"), "version", "params.textDocument");
  if (!version.is_number_integer()) throw BadParams{"params.textDocument.version must be an integer"};
  const json& changes = member(params, "contentChanges", "params");
  if (!changes.is_array()) throw BadParams{"params.contentChanges must be an array"};
  Document& doc = it->second;
  std::string text = doc.source->text;
  for (const json& c : changes) {
    std::string replacement = string_at(c, "text", "params.contentChanges[]");
    if (!c.contains("range")) {
      text = std::move(replacement);
      continue;
    }
    // An edit of a range: this server asks for the whole text, but a client may still send one.
    SourceFile current(doc.path, text);
    const json& range = member(c, "range", "params.contentChanges[]");
    std::size_t from = offset_of(current, position_at(range, "start", "range"), encoding_);
    std::size_t to = offset_of(current, position_at(range, "end", "range"), encoding_);
    if (to < from) throw BadParams{"params.contentChanges[].range ends before it starts"};
    text.replace(from, to - from, replacement);
  }
  doc.version = version.get<long long>();
  check(doc, std::move(text));
}

void Server::close(const json& params) {
  std::string uri = uri_of(params);
  if (documents_.erase(uri) == 0) return;
  // Its problems leave the editor with it, as they would with the file closed in a terminal.
  outbox_.push_back({{"jsonrpc", "2.0"},
                     {"method", "textDocument/publishDiagnostics"},
                     {"params", {{"uri", uri}, {"diagnostics", json::array()}}}});
}

// A note's file as a URI: the document's own, the fleet file's, or any other file it names.
PublishOptions Server::publishing(const Document& doc) const {
  PublishOptions options;
  options.encoding = encoding_;
  options.related_information = related_information_;
  options.uri_of = [uri = doc.uri, path = doc.path, fleet = fleet_path_](const Diagnostic& d) {
    if (!d.has_file || d.path == path) return uri;
    if (d.path == fleet) return path_to_uri(fleet);
    std::error_code ec;
    std::filesystem::path absolute = std::filesystem::absolute(d.path, ec);
    return path_to_uri(ec ? d.path : absolute.string());
  };
  return options;
}

void Server::check(Document& doc, std::string text) {
  CheckResult r = update(doc, std::move(text), fleet_path_, fleet_);
  outbox_.push_back({{"jsonrpc", "2.0"},
                     {"method", "textDocument/publishDiagnostics"},
                     {"params",
                      {{"uri", doc.uri},
                       {"version", doc.version},
                       {"diagnostics", diagnostics_json(r.mission, publishing(doc))}}}});
  publish_fleet(r.fleet, publishing(doc));
}

// The fleet file's problems go to its own URI, once per change: every keystroke in a
// mission re-reads the fleet file, but repeats nothing the editor already shows.
void Server::publish_fleet(const std::vector<Published>& items, const PublishOptions& options) {
  if (fleet_path_.empty()) return;
  json diagnostics = diagnostics_json(items, options);
  if (diagnostics == fleet_published_) return;
  fleet_published_ = diagnostics;
  outbox_.push_back({{"jsonrpc", "2.0"},
                     {"method", "textDocument/publishDiagnostics"},
                     {"params", {{"uri", path_to_uri(fleet_path_)}, {"diagnostics", diagnostics}}}});
}

int serve_stdio(const ServerOptions& options) {
  // A client that went away must end the server with a status, not a signal.
  std::signal(SIGPIPE, SIG_IGN);
  Server server(options);
  FrameReader reader(STDIN_FILENO);
  bool output_open = true;
  auto send = [&](const json& m) {
    if (output_open) output_open = write_frame(STDOUT_FILENO, m);
  };
  for (;;) {
    Frame f = reader.next();
    if (f.kind == Frame::Kind::end) return server.shutting_down() ? 0 : 1;
    if (f.kind == Frame::Kind::framing_error) {
      send(server.framing_error(f.error));
      continue;
    }
    if (std::optional<int> status = server.handle(f.body, send)) return *status;
    if (!output_open) return 1;
  }
}

}  // namespace eamos::lsp
