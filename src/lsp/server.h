#pragma once
// `eamos lsp`: the Language Server Protocol (3.17) over a pair of file descriptors, JSON-RPC
// 2.0 framed by Content-Length. One thread, one message at a time, in order; every answer
// comes from the compiler's own stages, so the editor says what `eamos check` says.
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "fleet/fleet.h"
#include "lsp/document.h"
#include "lsp/text.h"

namespace eamos::lsp {

struct ServerOptions {
  /// The fleet file missions are checked against, as `eamos check --fleet`; "" = none.
  /// The client's initializationOptions {"fleet": PATH} replaces it.
  std::string fleet;
};

class Server {
 public:
  explicit Server(ServerOptions options) : options_(std::move(options)) {}

  /// Handles one message (the JSON text of a frame); `send` gets every message to write, in
  /// order. Returns the exit status once `exit` arrived (0 after `shutdown`, else 1).
  template <class Send>
  std::optional<int> handle(const std::string& body, Send&& send) {
    outbox_.clear();
    std::optional<int> status = dispatch(body);
    for (const auto& m : outbox_) send(m);
    outbox_.clear();
    return status;
  }
  /// Answers a frame that could not be read (bad header, truncated): a JSON-RPC error.
  nlohmann::json framing_error(const std::string& reason) const;
  /// True once `shutdown` was answered: the end of input is then a clean exit.
  bool shutting_down() const { return shutting_down_; }

 private:
  std::optional<int> dispatch(const std::string& body);
  /// Whether `msg` (with `id`, when `has_id`) is a request or notification this server takes
  /// (jsonrpc 2.0, a string method); when not, the error is replied and `msg` dropped.
  bool takes(const nlohmann::json& msg, const nlohmann::json& id, bool has_id);
  void request(const nlohmann::json& id, const std::string& method, const nlohmann::json& params);
  void notification(const std::string& method, const nlohmann::json& params);
  nlohmann::json initialize(const nlohmann::json& params);
  nlohmann::json document_request(const std::string& method, const nlohmann::json& params);
  void open(const nlohmann::json& params);
  void change(const nlohmann::json& params);
  void close(const nlohmann::json& params);
  void check(Document& doc, std::string text);
  void publish_fleet(const std::vector<Published>& items, const PublishOptions& options);
  PublishOptions publishing(const Document& doc) const;
  void reply(const nlohmann::json& id, nlohmann::json result);
  void reply_error(const nlohmann::json& id, int code, const std::string& message);

  ServerOptions options_;
  bool initialized_ = false;
  bool shutting_down_ = false;
  Encoding encoding_ = Encoding::utf16;
  bool hierarchical_symbols_ = false;
  bool related_information_ = false;  ///< the client shows a diagnostic's notes with it
  std::string fleet_path_;                     ///< absolute, or as given when relative to no known folder
  fleet::Fleet fleet_;                         ///< as loaded by the last check
  std::map<std::string, Document> documents_;  ///< by URI
  nlohmann::json fleet_published_ = nlohmann::json::array();
  std::vector<nlohmann::json> outbox_;
};

/// Serves the protocol on standard input and output until `exit` or the end of input;
/// returns the process's exit status.
int serve_stdio(const ServerOptions& options);

}  // namespace eamos::lsp
