// Wire: one direction of a serial link at a fixed byte rate. Bytes written at `now` come out when
// their last bit would have arrived (8N1: ten bits a byte), one after another. Rate 0: no limit.
#pragma once

#include <chrono>
#include <deque>
#include <string>
#include <string_view>

namespace salient::protocol::sim {

using Micros = std::chrono::microseconds;

class Wire {
 public:
  explicit Wire(double bytes_per_second = 0) : rate_(bytes_per_second) {}

  void push(std::string_view bytes, Micros now);
  std::string pop(Micros now);  // every byte that has arrived by `now`
  Micros next_arrival() const;  // when the next byte arrives; Micros::max() when empty
  Micros last_arrival() const;  // when the last byte pushed so far arrives; Micros::max() when empty
  bool empty() const { return chunks_.empty(); }
  void clear() {  // what was on the line is lost, and the line is free at once
    chunks_.clear();
    free_at_us_ = 0;
  }

 private:
  struct Chunk {
    std::string bytes;
    double start_us;  // when its first bit went out
    std::size_t taken = 0;
  };
  double rate_;
  double free_at_us_ = 0;  // when the line is free for the next byte
  std::deque<Chunk> chunks_;
};

}  // namespace salient::protocol::sim
