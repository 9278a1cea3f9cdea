#include "monitor/server.h"

#include <arpa/inet.h>
#include <civetweb.h>
#include <sys/socket.h>

#include <cctype>
#include <cstring>

#include "monitor/web_assets.h"

namespace eamos::monitor {

namespace {

// Beyond this a mission keeps flying and the page misses events (it is told how many).
constexpr std::size_t max_history = 5'000'000;

bool is_loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1" || host == "[::1]";
}

// The Host header without its port ("127.0.0.1:8080" → "127.0.0.1"), and its port.
void split_host(const std::string& header, std::string& host, std::string& port) {
  std::size_t colon = header.rfind(':');
  std::size_t bracket = header.rfind(']');
  if (colon == std::string::npos || (bracket != std::string::npos && colon < bracket)) {
    host = header;
    port = "";
    return;
  }
  host = header.substr(0, colon);
  port = header.substr(colon + 1);
}

void send_status(mg_connection* conn, int code, const char* text) {
  mg_printf(conn,
            "HTTP/1.1 %d %s\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: %zu\r\n"
            "Connection: close\r\n\r\n%s",
            code, text, std::strlen(text), text);
}

// A numeric address, as the operating system reads one: civetweb itself takes each of the
// four numbers modulo 256 (999.1.1.1 listened on 231.1.1.1).
bool parse_host(std::string host, std::string& out, std::string& error) {
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  if (host == "localhost") host = "127.0.0.1";
  unsigned char address[16];
  if (host.size() < 64 && (inet_pton(AF_INET, host.c_str(), address) == 1 || inet_pton(AF_INET6, host.c_str(), address) == 1)) {
    out = host;
    return true;
  }
  std::string shown = host.size() > 64 ? host.substr(0, 64) + "…" : host;
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 0x20) c = '?';
  error = "'" + shown + "' is not an IP address; give a numeric address of this machine: 127.0.0.1 (this machine "
          "only, the default), 0.0.0.0 (every interface), ::1 or an address of one interface";
  return false;
}

}  // namespace

bool parse_endpoint(const std::string& text, Endpoint& out, std::string& error) {
  std::string host = "127.0.0.1", port = text;
  std::size_t colon = text.rfind(':');
  if (colon != std::string::npos) {
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  bool port_ok = !port.empty() && port.size() <= 5;
  for (char c : port) port_ok = port_ok && std::isdigit(static_cast<unsigned char>(c));
  if (!port_ok || std::stoi(port) > 65535) {
    error = "'" + port + "' is not a port number; give 0 to 65535 (0: any free port), as [HOST:]PORT";
    return false;
  }
  if (!parse_host(host, out.host, error)) return false;
  out.port = std::stoi(port);
  return true;
}

MonitorServer::MonitorServer(ServerLimits limits) : limits_(limits) { mg_init_library(0); }

MonitorServer::~MonitorServer() {
  stop();
  mg_exit_library();
}

void MonitorServer::set_mission(std::string mission_json) { mission_json_ = std::move(mission_json); }

bool MonitorServer::start(const Endpoint& at, std::string& error) {
  std::string ports = at.host.find(':') != std::string::npos ? "[" + at.host + "]:" + std::to_string(at.port)
                                                             : at.host + ":" + std::to_string(at.port);
  // Every connection holds one of civetweb's threads for its life (a WebSocket for as long
  // as its page is open): the page's own requests keep threads of their own.
  std::string threads = std::to_string(limits_.max_websockets + limits_.http_workers);
  std::string timeout = std::to_string(limits_.header_timeout_ms);
  const char* options[] = {"listening_ports", ports.c_str(), "num_threads", threads.c_str(),
                           "enable_directory_listing", "no", "enable_keep_alive", "no",
                           // Bounds how long a request's headers may take in all, and how long
                           // a write to a browser may go without progress.
                           "request_timeout_ms", timeout.c_str(),
                           // The server pings and times out the pages itself (websocket_clients.cpp):
                           // civetweb's own pings would hide the answers it needs to see.
                           "enable_websocket_ping_pong", "no", "websocket_timeout_ms", "1000",
                           // Each live event is a small write: with Nagle's algorithm one waits for
                           // the browser's delayed ACK of the one before (tens of ms on loopback).
                           "tcp_nodelay", "1", nullptr};
  mg_callbacks callbacks{};
  // civetweb would print to stderr; the error text is returned instead.
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };
  context_ = mg_start(&callbacks, this, options);
  if (!context_) {
    error = "cannot serve the monitor on " + ports + " (in use, or not an address of this machine); "
            "choose another with --monitor HOST:PORT or --port";
    return false;
  }
  mg_server_port bound[4];
  int n = mg_get_server_ports(context_, 4, bound);
  port_ = n > 0 ? bound[0].port : at.port;
  loopback_ = is_loopback(at.host);
  std::string shown = at.host == "0.0.0.0" || at.host == "::" ? "127.0.0.1" : at.host;
  if (shown.find(':') != std::string::npos) shown = "[" + shown + "]";
  url_ = "http://" + shown + ":" + std::to_string(port_) + "/";
  mg_set_request_handler(context_, "/", &MonitorServer::on_http, this);
  mg_set_websocket_handler(context_, "/ws", &MonitorServer::on_ws_connect, &MonitorServer::on_ws_ready,
                           &MonitorServer::on_ws_data, &MonitorServer::on_ws_close, this);
  watchdog_ = std::thread([this] { watch_loop(); });
  return true;
}

void MonitorServer::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_ && !context_) return;
    stopping_ = true;
    // Writers blocked on a browser that does not read return at once.
    for (auto& [conn, client] : clients_)
      if (client->fd >= 0) shutdown(client->fd, SHUT_RDWR);
  }
  changed_.notify_all();
  watch_wake_.notify_all();
  if (watchdog_.joinable()) watchdog_.join();
  if (context_) mg_stop(context_);  // closes every connection: each close joins its writer
  context_ = nullptr;
}

void MonitorServer::append(std::string event_json, double emitted_ms) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (events_.size() >= max_history) {
      ++dropped_;
      return;
    }
    events_.push_back(Event{std::move(event_json), emitted_ms, Clock::now()});
  }
  changed_.notify_all();
}

void MonitorServer::finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    finished_ = true;
  }
  changed_.notify_all();
}

std::size_t MonitorServer::event_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_.size();
}

std::size_t MonitorServer::dropped_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

std::size_t MonitorServer::client_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return clients_.size();
}

std::size_t MonitorServer::dropped_clients() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_clients_;
}

// A page on another site must not read the mission through a name that points here
// (DNS rebinding): on a loopback address only loopback names are served.
bool MonitorServer::host_allowed(const mg_connection* conn) const {
  if (!loopback_) return true;
  const char* header = mg_get_header(conn, "Host");
  if (!header) return false;
  std::string host, port;
  split_host(header, host, port);
  return is_loopback(host) && port == std::to_string(port_);
}

int MonitorServer::on_http(mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<MonitorServer*>(self_ptr);
  const mg_request_info* info = mg_get_request_info(conn);
  bool head = std::strcmp(info->request_method, "HEAD") == 0;
  if (std::strcmp(info->request_method, "GET") != 0 && !head) {
    send_status(conn, 405, "The monitor only shows: GET and the WebSocket, nothing that changes anything.");
    return 405;
  }
  if (!self->host_allowed(conn)) {
    send_status(conn, 403, "Open the monitor through the address it printed.");
    return 403;
  }
  const WebAsset* asset = find_web_asset(info->local_uri ? info->local_uri : "");
  if (!asset) {
    send_status(conn, 404, "Not found.");
    return 404;
  }
  mg_printf(conn,
            "HTTP/1.1 200 OK\r\nContent-Type: %s\r\nContent-Length: %zu\r\nCache-Control: no-store\r\n"
            "X-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\nReferrer-Policy: no-referrer\r\n"
            "Content-Security-Policy: default-src 'self'; img-src 'self' data:; style-src 'self' 'unsafe-inline'; "
            "connect-src 'self'; frame-ancestors 'none'\r\nConnection: close\r\n\r\n",
            asset->content_type, asset->size);
  if (!head) mg_write(conn, asset->data, asset->size);
  return 200;
}

}  // namespace eamos::monitor
