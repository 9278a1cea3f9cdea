#pragma once
// The monitor's web server: serves the built-in page and, over one WebSocket per browser,
// the mission (its source, drones and graphs) and its trace events, first the history so far
// and then each new event as it comes. It only ever reads: GET (and HEAD) of the page and the
// WebSocket; anything a browser sends on the WebSocket is ignored. The mission side only
// appends events under a short lock; sending happens on the server's own thread, so a slow
// or vanished browser never holds up a mission.
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
  std::string host = "127.0.0.1";
  int port = 8080;  ///< 0: any free port (the URL says which)
};

/// Parses "[HOST:]PORT"; false with `error` set ("... ; how to fix") when it is not one.
bool parse_endpoint(const std::string& text, Endpoint& out, std::string& error);

class MonitorServer {
 public:
  MonitorServer();
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

 private:
  struct Client {
    std::size_t cursor = 0;  ///< events already sent
    bool ready = false;
    bool sent_mission = false;
    bool sent_finish = false;
  };
  static int on_http(mg_connection* conn, void* self);
  static int on_ws_connect(const mg_connection* conn, void* self);
  static void on_ws_ready(mg_connection* conn, void* self);
  static int on_ws_data(mg_connection* conn, int bits, char* data, std::size_t len, void* self);
  static void on_ws_close(const mg_connection* conn, void* self);
  bool host_allowed(const mg_connection* conn) const;
  void send_loop();
  void send_pending(mg_connection* conn, Client& client);

  mg_context* context_ = nullptr;
  std::string url_;
  bool loopback_ = true;
  int port_ = 0;
  std::string mission_json_;

  mutable std::mutex events_mutex_;
  std::condition_variable events_changed_;
  struct Event {
    std::string json;
    double emitted_ms = 0;
  };
  std::deque<Event> events_;
  std::size_t dropped_ = 0;
  bool news_ = false;  ///< something for the sender since it last looked (a notify alone can be missed)
  bool finished_ = false;
  bool stopping_ = false;

  mutable std::mutex clients_mutex_;
  std::map<const mg_connection*, Client> clients_;
  std::thread sender_;
};

}  // namespace eamos::monitor
