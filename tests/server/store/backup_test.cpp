#include "server/store/backup.hpp"

#include <doctest/doctest.h>
#include <sys/stat.h>

#include <fstream>

#include "server/store/data_dir_lock.hpp"
#include "server/store/print_store.hpp"
#include "server/store/store.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::server;
namespace fs = std::filesystem;

namespace {

fs::path object(const fs::path& root, const std::string& d) {
  return root / "files" / "objects" / d.substr(0, 2) / d.substr(2);
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const StoreError& e) {
    return e.what();
  }
  return "(no error)";
}

// Data with two prints (a.gcode, b.gcode) and one stored file nothing refers to.
// (A name per test: Store keeps one connection per path and thread.)
struct Data {
  explicit Data(const std::string& name) : dir(name) {}
  salient::test::ScratchDir dir;
  Store store{dir.path};
  PrintStore prints{store.db()};
  std::string a = store.files().put("G28 ; a\n"), b = store.files().put("G28 ; b\n");
  std::string loose = store.files().put("nobody refers to this");
  std::int64_t print_a = prints.create("sim", std::nullopt, a, "a.gcode", 1, 1.0).id;
  std::int64_t print_b = prints.create("sim", std::nullopt, b, "b.gcode", 1, 2.0).id;
};

}  // namespace

TEST_CASE("backup: the database and the files it refers to, verified, restored into a new directory") {
  Data data("backup-data-1");
  salient::test::ScratchDir out("backup-out");
  fs::create_directories(out.path);
  const BackupSummary s = backup_data_dir(data.dir.path, out.path / "b");
  CHECK(s.files == 2);
  CHECK(s.snapshots == 1);
  CHECK(fs::exists(object(out.path / "b", data.a)));
  CHECK(!fs::exists(object(out.path / "b", data.loose)));  // unreferenced: not part of the backup
  CHECK(fs::exists(out.path / "b" / "salient-backup.json"));
  CHECK(verify_backup(out.path / "b").files == 2);
  // Nothing but the backup is left beside it.
  CHECK(std::distance(fs::directory_iterator(out.path), fs::directory_iterator()) == 1);

  const BackupSummary r = restore_data_dir(out.path / "b", out.path / "restored", false);
  CHECK(r.files == 2);
  Store restored(out.path / "restored");
  PrintStore prints(restored.db());
  REQUIRE(prints.get(data.print_b));
  CHECK(restored.files().read(prints.get(data.print_b)->file_digest) == "G28 ; b\n");
  CHECK(message_of([&] { backup_data_dir(data.dir.path, out.path / "b"); }).find("already exists") !=
        std::string::npos);
}

TEST_CASE("backup: a sweep that removes a file between the snapshot and the copy makes it snapshot again") {
  Data data("backup-data-2");
  salient::test::ScratchDir out("backup-race");
  fs::create_directories(out.path);
  // As the daemon would, between the backup's snapshot and its copying: the print row goes,
  // then its file is swept.
  const BackupSummary s = backup_data_dir(data.dir.path, out.path / "b", [&](int snapshot) {
    if (snapshot != 1) return;
    data.store.db().prepare("DELETE FROM prints WHERE id = ?").bind(1, data.print_b).run();
    CHECK(data.store.remove_unreferenced({data.b}) == 1);
  });
  CHECK(s.snapshots == 2);
  CHECK(s.files == 1);
  CHECK(verify_backup(out.path / "b").files == 1);
  CHECK(!fs::exists(object(out.path / "b", data.b)));
}

TEST_CASE("restore: refuses what is not a backup, a damaged one, a busy or non-empty data directory") {
  Data data("backup-data-3");
  salient::test::ScratchDir out("backup-bad");
  fs::create_directories(out.path);
  const fs::path b = out.path / "b";
  backup_data_dir(data.dir.path, b);
  const fs::path target = out.path / "target";

  CHECK(message_of([&] { restore_data_dir(data.dir.path, target, false); }).find("not a salientd backup") !=
        std::string::npos);
  // A data directory in use by a daemon (its lock held).
  {
    const DataDirLock held(target);
    CHECK(message_of([&] { restore_data_dir(b, target, false); }).find("another salientd") !=
          std::string::npos);
  }
  // Not empty: refused, then replaced with --force.
  std::ofstream(target / "something") << "x";
  CHECK(message_of([&] { restore_data_dir(b, target, false); }).find("not empty") != std::string::npos);
  CHECK(fs::exists(target / "something"));
  restore_data_dir(b, target, true);
  CHECK(!fs::exists(target / "something"));
  CHECK(fs::exists(target / "salient.db"));

  // A stored file with other bytes than its name says.
  std::ofstream(object(b, data.a), std::ios::trunc) << "tampered";
  const fs::path fresh = out.path / "fresh";
  CHECK(message_of([&] { restore_data_dir(b, fresh, false); }).find("other bytes") != std::string::npos);
  CHECK(!fs::exists(fresh / "salient.db"));
  fs::remove(object(b, data.a));
  CHECK(message_of([&] { verify_backup(b); }).find("missing") != std::string::npos);
  // A database that is not one.
  std::ofstream(b / "salient.db", std::ios::trunc) << std::string(8192, 'x');
  CHECK(message_of([&] { verify_backup(b); }).find("damaged") != std::string::npos);
  CHECK(!fs::exists(fresh));  // verified before anything is written
}

TEST_CASE("restore: refuses a backup holding a symbolic link or anything but plain files and directories") {
  Data data("backup-data-4");
  salient::test::ScratchDir out("backup-links");
  fs::create_directories(out.path);
  const fs::path secret = out.path / "secret";
  std::ofstream(secret) << "root:$6$not-for-the-daemon\n";

  // The api-key a link to a file outside (as /etc/shadow, restored by root): refused, nothing copied.
  const fs::path b = out.path / "b";
  backup_data_dir(data.dir.path, b);
  fs::remove(b / "api-key");
  fs::create_symlink(secret, b / "api-key");
  const fs::path target = out.path / "target";
  const std::string linked = message_of([&] { restore_data_dir(b, target, false); });
  CHECK(linked.find("api-key") != std::string::npos);
  CHECK(linked.find("symbolic link") != std::string::npos);
  CHECK(!fs::exists(target / "api-key"));
  CHECK(!fs::exists(target / "salient.db"));

  // A stored file's directory a link (its file then read through it): refused too.
  const fs::path c = out.path / "c";
  backup_data_dir(data.dir.path, c);
  const fs::path shard = object(c, data.a).parent_path();
  fs::rename(shard, out.path / "elsewhere");
  fs::create_directory_symlink(out.path / "elsewhere", shard);
  CHECK(message_of([&] { verify_backup(c); }).find("symbolic link") != std::string::npos);

  // A named pipe among the files: refused, not read (a read would block).
  const fs::path d = out.path / "d";
  backup_data_dir(data.dir.path, d);
  fs::remove(d / "api-key");
  REQUIRE(::mkfifo((d / "api-key").c_str(), 0600) == 0);
  CHECK(message_of([&] { verify_backup(d); }).find("not a regular file") != std::string::npos);
}
