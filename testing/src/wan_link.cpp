// wan_link: an emulated wide-area link between two network namespaces, in user space.
//
// The kernels this project is tested on may lack sch_netem (tc's delay and loss), so the link is
// emulated here: a TUN device in each namespace, point to point (10.88.0.1 in the first, 10.88.0.2
// in the second), and this process between them carrying every IP packet with
//   - a one-way delay (each direction),
//   - random loss (seeded: runs repeat),
//   - a rate: packets leave a direction's queue no faster than the rate, the queue is drop-tail
//     at --queue-bytes (a bottleneck's buffer),
//   - outages: SIGUSR1 takes the link down (everything dropped), SIGUSR2 brings it back.
// It prints "wan_link: up" once both ends are configured, and runs until SIGTERM/SIGINT.
//
//   wan_link --ns-a NAME --ns-b NAME [--delay-ms 20] [--loss 0.01] [--rate-kbit 5000]
//            [--queue-bytes 65536] [--seed 1]
// Needs CAP_NET_ADMIN (root): it enters the namespaces to make the devices.
#include <fcntl.h>
#include <linux/if.h>
#include <linux/if_tun.h>
#include <poll.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> gStop{false}, gDown{false};

struct Options {
  std::string nsA, nsB;
  double delayMs = 20.0, loss = 0.0, rateKbit = 0.0;  // rate 0: unlimited
  size_t queueBytes = 65536;
  uint64_t seed = 1;
};

[[noreturn]] void die(const std::string& why) {
  std::fprintf(stderr, "wan_link: %s\n", why.c_str());
  std::exit(2);
}

double number(const char* text, const char* name, double lo, double hi) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(v >= lo && v <= hi))
    die(std::string(name) + " takes a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], not '" + text + "'");
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) die("option " + a + " needs a value");
    const char* v = argv[++i];
    if (a == "--ns-a") o.nsA = v;
    else if (a == "--ns-b") o.nsB = v;
    else if (a == "--delay-ms") o.delayMs = number(v, "--delay-ms", 0, 10000);
    else if (a == "--loss") o.loss = number(v, "--loss", 0, 1);
    else if (a == "--rate-kbit") o.rateKbit = number(v, "--rate-kbit", 0, 10'000'000);
    else if (a == "--queue-bytes") o.queueBytes = static_cast<size_t>(number(v, "--queue-bytes", 1500, 1 << 30));
    else if (a == "--seed") o.seed = static_cast<uint64_t>(number(v, "--seed", 0, 1e15));
    else die("unknown option " + a);
  }
  if (o.nsA.empty() || o.nsB.empty()) die("--ns-a and --ns-b are required");
  return o;
}

void enter(const std::string& ns) {
  const std::string path = ns == "." ? "/proc/1/ns/net" : "/var/run/netns/" + ns;
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) die("cannot open " + path + ": " + std::strerror(errno));
  if (setns(fd, CLONE_NEWNET) != 0) die("cannot enter " + path + ": " + std::strerror(errno));
  close(fd);
}

// A TUN device named `name` in the namespace we are in, up, with `self` and its peer `peer`.
int makeTun(const std::string& name, const std::string& self, const std::string& peer) {
  const int fd = open("/dev/net/tun", O_RDWR | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) die(std::string("cannot open /dev/net/tun: ") + std::strerror(errno));
  ifreq ifr{};
  ifr.ifr_flags = IFF_TUN | IFF_NO_PI;
  std::snprintf(ifr.ifr_name, IFNAMSIZ, "%s", name.c_str());
  if (ioctl(fd, TUNSETIFF, &ifr) != 0) die("cannot make " + name + ": " + std::strerror(errno));
  const std::string cmd = "ip addr add " + self + " peer " + peer + " dev " + name + " && ip link set " + name +
                          " up mtu 1500 && ip link set lo up";
  if (std::system(cmd.c_str()) != 0) die("cannot configure " + name);
  return fd;
}

// One direction of the link.
struct Direction {
  int from = -1, to = -1;
  struct Packet {
    std::vector<uint8_t> bytes;
    Clock::time_point due;
  };
  std::deque<Packet> queue;  // waiting for the rate (the bottleneck's buffer)
  std::deque<Packet> flying;  // past the rate, waiting out the delay
  size_t queued = 0;
  Clock::time_point free = Clock::now();  // when the rate lets the next packet leave
  uint64_t passed = 0, lost = 0, dropped = 0;
};

void onSignal(int s) {
  if (s == SIGUSR1) gDown = true;
  else if (s == SIGUSR2) gDown = false;
  else gStop = true;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  enter(o.nsA);
  const int tunA = makeTun("wana", "10.88.0.1", "10.88.0.2");
  enter(o.nsB);
  const int tunB = makeTun("wanb", "10.88.0.2", "10.88.0.1");
  for (int s : {SIGTERM, SIGINT, SIGUSR1, SIGUSR2}) std::signal(s, onSignal);
  std::mt19937_64 random(o.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const auto delay = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(o.delayMs));
  Direction dir[2];
  dir[0].from = tunA, dir[0].to = tunB;
  dir[1].from = tunB, dir[1].to = tunA;
  std::printf("wan_link: up (%s 10.88.0.1 <-> %s 10.88.0.2, %.1f ms, loss %.4f, %.0f kbit/s, queue %zu B)\n",
              o.nsA.c_str(), o.nsB.c_str(), o.delayMs, o.loss, o.rateKbit, o.queueBytes);
  std::fflush(stdout);
  std::vector<uint8_t> buffer(65536);
  while (!gStop) {
    const auto now = Clock::now();
    Clock::time_point next = now + std::chrono::milliseconds(100);
    for (Direction& d : dir) {
      // The rate: the head of the queue leaves when the link is free, then flies for the delay.
      while (!d.queue.empty() && d.free <= now) {
        Direction::Packet p = std::move(d.queue.front());
        d.queue.pop_front();
        d.queued -= p.bytes.size();
        const auto serialise = o.rateKbit > 0 ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                                    static_cast<double>(p.bytes.size()) * 8.0 / (o.rateKbit * 1000.0)))
                                              : Clock::duration::zero();
        d.free = std::max(d.free, now) + serialise;
        p.due = d.free + delay;
        d.flying.push_back(std::move(p));
      }
      while (!d.flying.empty() && d.flying.front().due <= now) {
        if (write(d.to, d.flying.front().bytes.data(), d.flying.front().bytes.size()) > 0) ++d.passed;
        d.flying.pop_front();
      }
      if (!d.queue.empty()) next = std::min(next, std::max(d.free, now));
      if (!d.flying.empty()) next = std::min(next, d.flying.front().due);
    }
    pollfd fds[2] = {{tunA, POLLIN, 0}, {tunB, POLLIN, 0}};
    const auto waitNs = std::clamp<long long>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(next - Clock::now()).count(), 0, 100'000'000);
    const timespec wait{0, static_cast<long>(waitNs)};
    if (ppoll(fds, 2, &wait, nullptr) < 0) {
      if (errno == EINTR) continue;
      die(std::string("poll: ") + std::strerror(errno));
    }
    for (int k = 0; k < 2; ++k) {
      if (!(fds[k].revents & POLLIN)) continue;
      for (;;) {
        const ssize_t n = read(fds[k].fd, buffer.data(), buffer.size());
        if (n <= 0) break;
        Direction& d = dir[k];
        if (gDown || (o.loss > 0 && uniform(random) < o.loss)) {
          ++d.lost;
          continue;
        }
        if (d.queued + static_cast<size_t>(n) > o.queueBytes) {
          ++d.dropped;  // the bottleneck's buffer is full
          continue;
        }
        d.queue.push_back({std::vector<uint8_t>(buffer.begin(), buffer.begin() + n), Clock::now()});
        d.queued += static_cast<size_t>(n);
      }
    }
  }
  std::printf("wan_link: a->b %llu passed, %llu lost, %llu dropped; b->a %llu passed, %llu lost, %llu dropped\n",
              static_cast<unsigned long long>(dir[0].passed), static_cast<unsigned long long>(dir[0].lost),
              static_cast<unsigned long long>(dir[0].dropped), static_cast<unsigned long long>(dir[1].passed),
              static_cast<unsigned long long>(dir[1].lost), static_cast<unsigned long long>(dir[1].dropped));
  return 0;
}
