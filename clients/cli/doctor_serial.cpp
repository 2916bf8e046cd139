// The machine's side of `salient doctor`: serial devices, who may open them, who holds them, and
// the services that interfere with new USB serial devices.
#include <dirent.h>
#include <grp.h>
#include <limits.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include "clients/cli/doctor.hpp"

namespace salient::cli::doctor {
namespace {

namespace fs = std::filesystem;

std::string real_path(const std::string& p) {
  char buf[PATH_MAX];
  return ::realpath(p.c_str(), buf) ? std::string(buf) : std::string();
}

std::vector<std::string> glob_dir(const std::string& dir, const std::string& prefix) {
  std::vector<std::string> out;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename().string().rfind(prefix, 0) == 0) out.push_back(it->path().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::string group_name(gid_t gid) {
  const group* g = ::getgrgid(gid);
  return g ? g->gr_name : std::to_string(gid);
}

bool in_group(gid_t gid) {
  if (::getegid() == gid) return true;
  std::vector<gid_t> groups(static_cast<std::size_t>(std::max(0, ::getgroups(0, nullptr))));
  const int n = ::getgroups(static_cast<int>(groups.size()), groups.data());
  return std::find(groups.begin(), groups.begin() + std::max(0, n), gid) != groups.begin() + std::max(0, n);
}

// Processes with the device open (their /proc/PID/fd links name it), not counting this one;
// `hidden` counts those whose descriptors this user may not read (other users', unless root).
std::vector<Process> holders(const std::string& device, int& hidden) {
  std::vector<Process> out;
  hidden = 0;
  for (const Process& p : processes()) {
    if (p.pid == ::getpid()) continue;
    std::error_code ec;
    fs::directory_iterator it("/proc/" + std::to_string(p.pid) + "/fd", ec);
    if (ec == std::errc::permission_denied) ++hidden;
    for (fs::directory_iterator end; !ec && it != end; it.increment(ec)) {
      std::error_code link_ec;
      if (fs::read_symlink(it->path(), link_ec).string() == device) {
        out.push_back(p);
        break;
      }
    }
  }
  return out;
}

Check permission_check(const std::string& shown, const std::string& device) {
  struct stat st {};
  ::stat(device.c_str(), &st);
  const std::string group = group_name(st.st_gid);
  if (::access(device.c_str(), R_OK | W_OK) == 0)
    return {Verdict::ok, "access", shown + ": this user can read and write it", ""};
  const std::string why = in_group(st.st_gid)
                              ? "this user is in group " + group + " but still may not open it"
                              : "this user is not in group " + group + " (the device's group)";
  return {Verdict::fail, "access", shown + ": " + why,
          "sudo usermod -aG " + group +
              " $USER, then log out and in again (salientd's own user: the package adds it)"};
}

Check holder_check(const std::string& shown, const std::string& device) {
  int hidden = 0;
  const std::vector<Process> h = holders(device, hidden);
  if (h.empty())
    return {Verdict::ok, "in use",
            shown + (hidden ? ": none of this user's processes has it open (other users' are hidden: "
                              "sudo salient doctor sees them)"
                            : ": no process has it open"),
            ""};
  std::string who;
  bool other = false;
  for (const Process& p : h) {
    who += (who.empty() ? "" : ", ") + p.name + " (pid " + std::to_string(p.pid) + ")";
    // salient-sim keeps its own pty's other end open: it is the (simulated) board, not a rival.
    other = other || (p.name != "salientd" && p.name != "salient-sim");
  }
  if (!other) return {Verdict::ok, "in use", shown + ": open by " + who, ""};
  return {Verdict::fail, "in use", shown + ": open by " + who,
          "a port talks to one program at a time: stop the other one (kill PID, or close that terminal "
          "program; ModemManager or brltty: see below)"};
}

}  // namespace

std::vector<Process> processes() {
  std::vector<Process> out;
  std::error_code ec;
  for (fs::directory_iterator it("/proc", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream comm(it->path() / "comm");
    Process p{std::stoi(name), {}};
    std::getline(comm, p.name);
    out.push_back(std::move(p));
  }
  return out;
}

std::vector<Check> serial_checks(const std::vector<std::string>& extra) {
  // Each device once, by its real path, shown with its stable names.
  std::map<std::string, std::vector<std::string>> names;
  std::vector<std::string> order;
  const auto add = [&](const std::string& shown, const std::string& real) {
    if (!names.count(real)) order.push_back(real);
    if (shown != real)
      names[real].push_back(shown);
    else
      names[real];
  };
  for (const std::string& link : glob_dir("/dev/serial/by-id", ""))
    if (const std::string r = real_path(link); !r.empty()) add(link, r);
  for (const std::string& d : glob_dir("/dev", "ttyACM")) add(d, d);
  for (const std::string& d : glob_dir("/dev", "ttyUSB")) add(d, d);
  std::vector<Check> out;
  for (const std::string& d : extra) {
    const std::string r = real_path(d);
    if (r.empty())
      out.push_back({Verdict::fail, "serial", d + ": no such device (a dangling link: unplugged?)",
                     "plug the printer in (and power it); `ls -l /dev/serial/by-id/` lists what is there"});
    else
      add(d, r);
  }
  if (order.empty() && out.empty())
    out.push_back({Verdict::warn, "serial",
                   "no serial device (/dev/serial/by-id/*, /dev/ttyACM*, /dev/ttyUSB*)",
                   "plug the printer in and power it; `sudo dmesg | tail` shows whether the kernel saw it"});
  for (const std::string& real : order) {
    std::string shown = real;
    for (const std::string& n : names[real]) shown += (shown == real ? " = " : ", ") + n;
    out.push_back({Verdict::ok, "serial", shown + " present", ""});
    out.push_back(permission_check(real, real));
    out.push_back(holder_check(real, real));
  }
  return out;
}

std::vector<Check> interference_checks() {
  std::vector<Check> out;
  bool mm = false, brltty_running = false;
  for (const Process& p : processes()) {
    mm = mm || p.name == "ModemManager";
    brltty_running = brltty_running || p.name == "brltty";
  }
  if (mm)
    out.push_back({Verdict::warn, "ModemManager",
                   "running: it probes new ttyACM devices with AT commands, which a printer takes as G-code",
                   "install salient's udev rule (ENV{ID_MM_DEVICE_IGNORE}=\"1\" for printer boards), or "
                   "sudo systemctl disable --now ModemManager"});
  else
    out.push_back({Verdict::ok, "ModemManager", "not running", ""});
  std::error_code ec;
  const bool brltty_installed = fs::exists("/usr/bin/brltty", ec) || fs::exists("/bin/brltty", ec);
  if (brltty_running || brltty_installed)
    out.push_back(
        {Verdict::warn, "brltty",
         std::string(brltty_running ? "running" : "installed") +
             ": its udev rules claim CH340/CH341 USB serial adapters (1a86:7523), common on printer "
             "boards, and the ttyUSB device vanishes",
         "sudo apt remove brltty (unless a braille display is used)"});
  else
    out.push_back({Verdict::ok, "brltty", "not installed", ""});
  return out;
}

}  // namespace salient::cli::doctor
