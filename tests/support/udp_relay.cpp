// eamos-udp-relay: the bad network of the namespace tests (tests/launch/netns_test.cpp).
// The kernel here has no netem, so the tests put each DEX in its own network namespace,
// reachable from the others only through this process: it listens on the relay address
// for every Cyclone DDS port of every participant (ports are fixed by participant index)
// and forwards each datagram to the namespace that owns the port, losing, delaying and
// jittering them, and cutting whole links on command.
//
//   eamos-udp-relay --listen 10.77.0.1 --route 7660=10.77.1.2 ... --link Drone1=10.77.1.2 ...
//                   [--loss 0.1] [--delay 0.05] [--jitter 0.01] [--seed 1]
//
// Commands on standard input, one a line, each answered "ok ..." on standard output:
// `cut LINK [SECONDS]` (drop everything from and to it; healed after SECONDS, printing
// "healed LINK", when given), `heal LINK`, `loss P`. "ready" is printed
// once every port is bound. At EOF of standard input it prints per link what it forwarded
// and dropped, and exits.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <map>
#include <queue>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

double now_s() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

struct Route {
  int fd = -1;
  std::uint16_t port = 0;
  sockaddr_in to{};
};

struct Pending {
  double due;
  std::uint64_t seq;
  sockaddr_in to;
  std::vector<char> data;
  bool operator>(const Pending& o) const { return due != o.due ? due > o.due : seq > o.seq; }
};

struct LinkStats {
  std::uint64_t forwarded = 0, lost = 0, cut = 0;
};

struct Relay {
  std::string listen;
  std::vector<Route> routes;
  std::map<std::uint32_t, std::string> links;  ///< address (network order) → link name
  std::map<std::string, bool> cut;
  std::map<std::string, double> heal_at;  ///< timed cuts: when they end
  std::map<std::string, LinkStats> stats;
  double loss = 0.0, delay = 0.0, jitter = 0.0;
  std::mt19937_64 random{1};
  std::priority_queue<Pending, std::vector<Pending>, std::greater<Pending>> queue;
  std::uint64_t seq = 0;
  int out_fd = -1;
};

bool parse_address(const std::string& text, sockaddr_in& a) {
  a = {};
  a.sin_family = AF_INET;
  return inet_pton(AF_INET, text.c_str(), &a.sin_addr) == 1;
}

bool parse_args(int argc, char** argv, Relay& r, std::string& error) {
  std::vector<std::string> routes;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (i + 1 >= argc) {
      error = arg + " needs a value";
      return false;
    }
    std::string value = argv[++i];
    std::size_t eq = value.find('=');
    if (arg == "--listen") {
      r.listen = value;
    } else if (arg == "--route" && eq != std::string::npos) {
      routes.push_back(value);
    } else if (arg == "--link" && eq != std::string::npos) {
      sockaddr_in a;
      if (!parse_address(value.substr(eq + 1), a)) {
        error = "--link " + value + ": not an IPv4 address";
        return false;
      }
      r.links[a.sin_addr.s_addr] = value.substr(0, eq);
      r.cut[value.substr(0, eq)] = false;
    } else if (arg == "--loss" || arg == "--delay" || arg == "--jitter" || arg == "--seed") {
      char* end = nullptr;
      double v = std::strtod(value.c_str(), &end);
      if (*end != '\0' || !(v >= 0.0)) {
        error = arg + " " + value + ": not a non-negative number";
        return false;
      }
      if (arg == "--loss") r.loss = v;
      if (arg == "--delay") r.delay = v;
      if (arg == "--jitter") r.jitter = v;
      if (arg == "--seed") r.random.seed(static_cast<std::uint64_t>(v));
    } else {
      error = "unknown or malformed argument " + arg + " " + value;
      return false;
    }
  }
  if (r.listen.empty() || routes.empty()) {
    error = "--listen and at least one --route PORT=ADDRESS are needed";
    return false;
  }
  for (const std::string& text : routes) {
    std::size_t eq = text.find('=');
    Route route;
    route.port = static_cast<std::uint16_t>(std::atoi(text.substr(0, eq).c_str()));
    if (route.port == 0 || !parse_address(text.substr(eq + 1), route.to)) {
      error = "--route " + text + ": expected PORT=IPv4-ADDRESS";
      return false;
    }
    route.to.sin_port = htons(route.port);
    r.routes.push_back(route);
  }
  return true;
}

bool bind_routes(Relay& r, std::string& error) {
  for (Route& route : r.routes) {
    sockaddr_in a;
    parse_address(r.listen, a);
    a.sin_port = htons(route.port);
    route.fd = socket(AF_INET, SOCK_DGRAM, 0);
    int big = 4 << 20;
    setsockopt(route.fd, SOL_SOCKET, SO_RCVBUF, &big, sizeof big);
    if (route.fd < 0 || bind(route.fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
      error = "cannot bind " + r.listen + ":" + std::to_string(route.port) + ": " + std::strerror(errno);
      return false;
    }
  }
  r.out_fd = socket(AF_INET, SOCK_DGRAM, 0);
  return r.out_fd >= 0;
}

std::string link_of(const Relay& r, const sockaddr_in& a) {
  auto it = r.links.find(a.sin_addr.s_addr);
  return it == r.links.end() ? "" : it->second;
}

void receive(Relay& r, const Route& route) {
  std::vector<char> buf(65536);
  sockaddr_in from{};
  socklen_t len = sizeof from;
  ssize_t n = recvfrom(route.fd, buf.data(), buf.size(), MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&from), &len);
  if (n < 0) return;
  buf.resize(static_cast<std::size_t>(n));
  std::string src = link_of(r, from), dst = link_of(r, route.to);
  // Counted against the drone's link (the ground's, when neither end is a drone's).
  std::string counted = !dst.empty() && dst != "Ground" ? dst : (!src.empty() ? src : dst);
  LinkStats& st = r.stats[counted];
  if ((!src.empty() && r.cut[src]) || (!dst.empty() && r.cut[dst])) {
    ++st.cut;
    return;
  }
  if (std::uniform_real_distribution<double>(0.0, 1.0)(r.random) < r.loss) {
    ++st.lost;
    return;
  }
  ++st.forwarded;
  double wait = r.delay + (r.jitter > 0 ? std::uniform_real_distribution<double>(-r.jitter, r.jitter)(r.random) : 0.0);
  r.queue.push({now_s() + std::max(0.0, wait), ++r.seq, route.to, std::move(buf)});
}

void send_due(Relay& r) {
  double now = now_s();
  while (!r.queue.empty() && r.queue.top().due <= now) {
    const Pending& p = r.queue.top();
    sendto(r.out_fd, p.data.data(), p.data.size(), 0, reinterpret_cast<const sockaddr*>(&p.to), sizeof p.to);
    r.queue.pop();
  }
}

/// One command line; false at "quit".
void command(Relay& r, const std::string& line) {
  std::istringstream in(line);
  std::string verb, arg;
  double seconds = 0.0;
  in >> verb >> arg >> seconds;
  if ((verb == "cut" || verb == "heal") && r.cut.count(arg)) {
    r.cut[arg] = verb == "cut";
    r.heal_at.erase(arg);
    if (verb == "cut" && seconds > 0) r.heal_at[arg] = now_s() + seconds;
  } else if (verb == "loss") {
    r.loss = std::atof(arg.c_str());
  } else {
    std::cout << "error: unknown command '" << line << "' (cut LINK, heal LINK, loss P)\n" << std::flush;
    return;
  }
  std::cout << "ok " << line << "\n" << std::flush;
}

void heal_due(Relay& r) {
  double now = now_s();
  for (auto it = r.heal_at.begin(); it != r.heal_at.end();) {
    if (it->second > now) {
      ++it;
      continue;
    }
    r.cut[it->first] = false;
    std::cout << "healed " << it->first << "\n" << std::flush;
    it = r.heal_at.erase(it);
  }
}

void print_stats(const Relay& r) {
  for (const auto& [link, st] : r.stats)
    std::cout << "link " << (link.empty() ? "?" : link) << ": forwarded " << st.forwarded << ", lost " << st.lost
              << ", cut " << st.cut << "\n";
  std::cout << std::flush;
}

int run(Relay& r) {
  std::string pending_input;
  for (;;) {
    std::vector<pollfd> fds;
    fds.push_back({STDIN_FILENO, POLLIN, 0});
    for (const Route& route : r.routes) fds.push_back({route.fd, POLLIN, 0});
    int timeout_ms = 20;  // also how late a timed cut heals, at most
    if (!r.queue.empty())
      timeout_ms = std::min(timeout_ms, std::max(0, static_cast<int>((r.queue.top().due - now_s()) * 1000.0)));
    if (poll(fds.data(), fds.size(), timeout_ms) < 0 && errno != EINTR) return 1;
    for (std::size_t i = 1; i < fds.size(); ++i)
      if (fds[i].revents & POLLIN) receive(r, r.routes[i - 1]);
    send_due(r);
    heal_due(r);
    if (fds[0].revents & (POLLIN | POLLHUP)) {
      char buf[512];
      ssize_t n = read(STDIN_FILENO, buf, sizeof buf);
      if (n <= 0) {
        print_stats(r);
        return 0;
      }
      pending_input.append(buf, static_cast<std::size_t>(n));
      for (std::size_t nl; (nl = pending_input.find('\n')) != std::string::npos;) {
        command(r, pending_input.substr(0, nl));
        pending_input.erase(0, nl + 1);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Relay r;
  std::string error;
  if (!parse_args(argc, argv, r, error) || !bind_routes(r, error)) {
    std::cerr << "eamos-udp-relay: error: " << error << "\n";
    return 1;
  }
  std::cout << "ready\n" << std::flush;
  return run(r);
}
