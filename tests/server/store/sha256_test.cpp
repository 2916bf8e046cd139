#include "server/store/sha256.hpp"

#include <doctest/doctest.h>

#include <string>

using salient::server::Sha256;
using salient::server::sha256_hex;

TEST_CASE("SHA-256 matches the FIPS 180-4 test vectors") {
  CHECK(sha256_hex("") == "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  CHECK(sha256_hex("abc") == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  CHECK(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq") ==
        "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  CHECK(sha256_hex(std::string(1000000, 'a')) ==
        "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST_CASE("SHA-256 fed in pieces of any size gives the same digest") {
  std::string data;
  for (int i = 0; i < 1000; ++i) data += static_cast<char>(i * 7919 % 251);
  const std::string whole = sha256_hex(data);
  for (std::size_t piece : {1u, 3u, 63u, 64u, 65u, 200u}) {
    Sha256 h;
    for (std::size_t at = 0; at < data.size(); at += piece)
      h.update(std::string_view(data).substr(at, piece));
    CHECK(h.hex() == whole);
  }
}
