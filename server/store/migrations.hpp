// The schema's migrations: one list for both backends. Entry i moves the schema from version i
// to i + 1; never edit one that has shipped: add another.
#pragma once

#include <string>

#include "server/store/database_url.hpp"

namespace salient::server {

int migration_count();
// Entry `index` in the dialect's words. The differences are spelled as tokens in the one text:
// {ID} an integer key the database numbers, {INT} a 64-bit integer, {REAL} a double, {NOW} the
// Unix time now, {USER} the column named user (a reserved word in PostgreSQL), {JOBS_ROWID} the
// insertion order SQLite keeps as rowid (an identity column on PostgreSQL).
std::string migration_sql(int index, Dialect dialect);

}  // namespace salient::server
