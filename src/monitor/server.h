#pragma once
// The monitor's web server: serves the built-in page and, over one WebSocket per browser,
// the mission (its source, drones and graphs) and its trace events, first the history so far
// and then each new event as it comes. It only ever reads: GET (and HEAD) of the page and the
// WebSocket; what a browser sends on the WebSocket only tells the server that it is still
// there. The mission side only appends events under a short lock. Each browser has a writer
// thread of its own, so a slow, stuck or vanished browser delays nobody but itself, and one
// that falls too far behind, stops answering or never says hello is dropped (its page
// reconnects and replays from the start); see docs/monitor.md, "Many browsers, slow ones".
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

struct mg_context;
struct mg_connection;

namespace eamos::monitor {

struct Endpoint {
  std::string host = "127.0.0.1";  ///< a numeric IPv4 or IPv6 address ("localhost" is 127.0.0.1)
  int port = 8080;  ///< 0: any free port (the URL says which)
};

/// Parses "[HOST:]PORT"; false with `error` set ("... ; how to fix") when it is not one.
/// HOST must be a numeric IPv4 address (four numbers 0-255), an IPv6 address (bare or in
/// brackets) or "localhost".
bool parse_endpoint(const std::string& text, Endpoint& out, std::string& error);

/// How the server keeps room for everyone (docs/monitor.md); the defaults are the product's,
/// a test may shorten them.
struct ServerLimits {
  int max_websockets = 32;   ///< pages at once; a new one may replace one that is not answering
  int http_workers = 64;     ///< threads for page requests beside the WebSockets' own
  int header_timeout_ms = 3000;      ///< a request's headers must arrive within this; a write that makes no progress as long fails
  double hello_timeout_s = 3.0;      ///< a WebSocket that has said nothing this long after its handshake is dropped
  double ping_interval_s = 2.0;      ///< the server pings every page this often
  double answer_timeout_s = 6.0;     ///< a page that leaves a ping unanswered this long is dropped
  double max_lag_s = 30.0;           ///< a page not yet sent an event appended this long ago is dropped
  /// After a message of events, a page's writer lets this long pass before the next, so that
  /// the events in between go out together: a browser handles each message as a task of its
  /// own, and a thousand drones emit thousands of events a second (one message each before).
  double batch_interval_s = 0.008;
};

class MonitorServer {
 public:
  explicit MonitorServer(ServerLimits limits = {});
  ~MonitorServer();
  MonitorServer(const MonitorServer&) = delete;
  MonitorServer& operator=(const MonitorServer&) = delete;

  /// The mission as the page shows it (mission_view.h); set before start().
  void set_mission(std::string mission_json);
  /// Starts listening; false with `error` set when the address cannot be used.
  bool start(const Endpoint& at, std::string& error);
  /// "http://127.0.0.1:8080/" once started.
  std::string url() const { return url_; }
  /// One trace event (a JSON object's text). Never blocks on a browser. `emitted_ms`: the wall
  /// clock (Unix ms) when the mission emitted it, sent beside it so a page can tell how late it
  /// drew it; 0 for a replay, whose events happened long ago.
  void append(std::string event_json, double emitted_ms = 0);
  /// The mission's trace is complete: pages show it as a replay from now on.
  void finish();
  void stop();

  std::size_t event_count() const;
  std::size_t dropped_count() const;
  std::size_t client_count() const;
  /// Browsers dropped so far (too slow, not answering, or replaced by a new page).
  std::size_t dropped_clients() const;

 private:
  using Clock = std::chrono::steady_clock;
  struct Client {
    mg_connection* conn = nullptr;
    int fd = -1;                 ///< its socket, to cut it when it is dropped (-1: not found)
    std::thread writer;
    std::size_t cursor = 0;      ///< events already sent
    std::size_t joined_at = 0;   ///< events there were when it connected: the rest are live for it
    Clock::time_point connected, ping_sent, last_ping;
    Clock::time_point caught_up{};  ///< when it had been sent the history it joined with
    bool ping_outstanding = false;
    bool ready = false;          ///< the handshake is done: its writer runs
    bool said_hello = false;
    bool closing = false;        ///< dropped or gone: its writer stops
    bool sent_finish = false;
  };
  struct Event {
    std::string json;
    double emitted_ms = 0;
    Clock::time_point appended;
  };
  struct Batch;

  static int on_http(mg_connection* conn, void* self);
  static int on_ws_connect(const mg_connection* conn, void* self);
  static void on_ws_ready(mg_connection* conn, void* self);
  static int on_ws_data(mg_connection* conn, int bits, char* data, std::size_t len, void* self);
  static void on_ws_close(const mg_connection* conn, void* self);
  bool host_allowed(const mg_connection* conn) const;
  bool admit(const mg_connection* conn);
  void write_loop(Client* client);
  bool write_pending(Client* client, std::unique_lock<std::mutex>& lock);
  void take_batch(const Client& client, Batch& batch) const;
  bool unresponsive(const Client& c, Clock::time_point now) const;
  const char* why_drop(const Client& c, Clock::time_point now) const;
  void drop(Client& c);
  void watch_loop();

  ServerLimits limits_;
  mg_context* context_ = nullptr;
  std::string url_;
  bool loopback_ = true;
  int port_ = 0;
  std::string mission_json_;

  // One lock for the events and the clients' bookkeeping, never held while writing to a socket.
  mutable std::mutex mutex_;
  std::condition_variable changed_;  ///< an event, the end, a client closing, or stop
  std::condition_variable watch_wake_;
  std::deque<Event> events_;
  std::size_t dropped_ = 0;
  std::size_t dropped_clients_ = 0;
  bool finished_ = false;
  bool stopping_ = false;
  std::map<const mg_connection*, std::unique_ptr<Client>> clients_;
  std::thread watchdog_;
};

}  // namespace eamos::monitor
