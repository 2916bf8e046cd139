#include "server/service/zeroconf.hpp"

#include <avahi-client/client.h>
#include <avahi-client/publish.h>
#include <avahi-common/alternative.h>
#include <avahi-common/error.h>
#include <avahi-common/malloc.h>
#include <avahi-common/thread-watch.h>
#include <unistd.h>

#include "server/build_info.hpp"

namespace salient::server {

// Everything below runs on Avahi's poll thread (callbacks), or under its lock (constructor,
// destructor), as avahi_threaded_poll requires.
struct ZeroconfAnnouncer::Impl {
  std::vector<ZeroconfService> services;
  std::function<void(const std::string&)> log;
  AvahiThreadedPoll* poll = nullptr;
  AvahiClient* client = nullptr;
  AvahiEntryGroup* group = nullptr;

  void publish(AvahiClient* c) {
    if (!group) group = avahi_entry_group_new(c, &Impl::on_group, this);
    if (!group) return log(std::string("zeroconf: ") + avahi_strerror(avahi_client_errno(c)));
    if (!avahi_entry_group_is_empty(group)) return;
    for (ZeroconfService& s : services) {
      AvahiStringList* txt = nullptr;
      for (auto it = s.txt.rbegin(); it != s.txt.rend(); ++it) txt = avahi_string_list_add(txt, it->c_str());
      // OctoPrint's own type for its clients, and _http._tcp so that a browser's list shows it.
      for (const char* type : {"_octoprint._tcp", "_http._tcp"}) {
        const int rc = avahi_entry_group_add_service_strlst(
            group, AVAHI_IF_UNSPEC, AVAHI_PROTO_UNSPEC, AvahiPublishFlags(0), s.name.c_str(), type, nullptr,
            nullptr, static_cast<uint16_t>(s.port), txt);
        if (rc == AVAHI_ERR_COLLISION) {
          avahi_string_list_free(txt);
          return rename();
        }
        if (rc < 0) {
          avahi_string_list_free(txt);
          return log(std::string("zeroconf: cannot add ") + type + ": " + avahi_strerror(rc));
        }
      }
      avahi_string_list_free(txt);
    }
    if (const int rc = avahi_entry_group_commit(group); rc < 0)
      log(std::string("zeroconf: cannot announce: ") + avahi_strerror(rc));
  }

  // Another host announces the same name: "NAME #2", as Avahi's own tools do.
  void rename() {
    for (ZeroconfService& s : services) {
      char* next = avahi_alternative_service_name(s.name.c_str());
      log("zeroconf: the name '" + s.name + "' is taken on the network; trying '" + next + "'");
      s.name = next;
      avahi_free(next);
    }
    avahi_entry_group_reset(group);
    publish(client);
  }

  static void on_group(AvahiEntryGroup* g, AvahiEntryGroupState state, void* self) {
    auto* me = static_cast<Impl*>(self);
    me->group = g;
    if (state == AVAHI_ENTRY_GROUP_ESTABLISHED) {
      for (const ZeroconfService& s : me->services)
        me->log("zeroconf: announced '" + s.name + "' as _octoprint._tcp and _http._tcp on port " +
                std::to_string(s.port));
    } else if (state == AVAHI_ENTRY_GROUP_COLLISION) {
      me->rename();
    } else if (state == AVAHI_ENTRY_GROUP_FAILURE) {
      me->log(std::string("zeroconf: ") +
              avahi_strerror(avahi_client_errno(avahi_entry_group_get_client(g))));
    }
  }

  static void on_client(AvahiClient* c, AvahiClientState state, void* self) {
    auto* me = static_cast<Impl*>(self);
    me->client = c;
    switch (state) {
      case AVAHI_CLIENT_S_RUNNING:
        me->publish(c);
        break;
      case AVAHI_CLIENT_S_COLLISION:
      case AVAHI_CLIENT_S_REGISTERING:  // the host's name changes: announce again once it is settled
        if (me->group) avahi_entry_group_reset(me->group);
        break;
      case AVAHI_CLIENT_CONNECTING:  // no avahi-daemon (yet): AVAHI_CLIENT_NO_FAIL waits for one
        me->log("zeroconf: avahi-daemon is not running; salientd will be announced when it is");
        me->group = nullptr;  // freed with the connection it belonged to
        break;
      case AVAHI_CLIENT_FAILURE:
        me->log(std::string("zeroconf: ") + avahi_strerror(avahi_client_errno(c)) + "; not announced");
        break;
    }
  }
};

ZeroconfAnnouncer::ZeroconfAnnouncer(std::vector<ZeroconfService> services,
                                     std::function<void(const std::string&)> log)
    : impl_(std::make_unique<Impl>()) {
  impl_->services = std::move(services);
  impl_->log = std::move(log);
  impl_->poll = avahi_threaded_poll_new();
  if (!impl_->poll) {
    impl_->log("zeroconf: cannot start Avahi's event loop; not announced");
    return;
  }
  int error = 0;
  avahi_threaded_poll_lock(impl_->poll);  // the callbacks below run from within avahi_client_new
  impl_->client = avahi_client_new(avahi_threaded_poll_get(impl_->poll), AVAHI_CLIENT_NO_FAIL,
                                   &Impl::on_client, impl_.get(), &error);
  avahi_threaded_poll_unlock(impl_->poll);
  if (!impl_->client) {
    impl_->log(std::string("zeroconf: ") + avahi_strerror(error) + "; not announced");
    return;
  }
  avahi_threaded_poll_start(impl_->poll);
}

ZeroconfAnnouncer::~ZeroconfAnnouncer() {
  if (!impl_->poll) return;
  avahi_threaded_poll_stop(impl_->poll);
  if (impl_->client) avahi_client_free(impl_->client);  // frees the group too: the services go
  avahi_threaded_poll_free(impl_->poll);
}

std::unique_ptr<ZeroconfAnnouncer> announce_octoprint(const std::string& name, unsigned port,
                                                      std::function<void(const std::string&)> log) {
  ZeroconfService s;
  s.name = name;
  if (s.name.empty()) {
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    s.name = std::string("salient on ") + host;
    if (s.name.size() > 63) s.name.resize(63);  // one DNS label
  }
  s.port = port;
  s.txt = {"path=/", "version=" + std::string(octoprint_version), "api=" + std::string(octoprint_api_version),
           "model=salientd " + std::string(version()), "vendor=salient"};
  return std::make_unique<ZeroconfAnnouncer>(std::vector<ZeroconfService>{std::move(s)}, std::move(log));
}

}  // namespace salient::server
