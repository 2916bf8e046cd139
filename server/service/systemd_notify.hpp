// What salientd tells systemd (sd_notify) and learns from it (is stderr the journal?). Every call
// is a no-op outside systemd: without NOTIFY_SOCKET nothing is sent, and a failure to send is
// ignored (the unit would then time out, which is the right outcome for a broken manager link).
#pragma once

#include <string>

namespace salient::server {

// READY=1 with a one-line STATUS: the HTTP socket listens and jobs and printers have started.
void notify_ready(const std::string& status);
// STOPPING=1: the daemon has begun its graceful stop (Type=notify units show "deactivating").
void notify_stopping();
// True when stderr is the stream systemd connected to the journal (JOURNAL_STREAM names its
// device and inode): the journal stamps each line itself, so our own stamp would be a duplicate.
bool stderr_is_journal();

}  // namespace salient::server
