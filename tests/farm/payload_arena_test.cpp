// The master's payload arena (master/payload_arena.h): pieces hold exactly the bytes added,
// from several threads at once, and a chunk goes back to the system once its pieces are released.
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "frep/master/payload_arena.h"

using frep::farm::PayloadArena;

TEST(PayloadArena, PiecesHoldTheirBytesAndChunksAreReturnedWhenEmptied) {
  PayloadArena arena(4096);
  std::vector<PayloadArena::Piece> pieces;
  for (int i = 0; i < 6; ++i) {
    const std::string bytes(3000, char('a' + i));
    pieces.push_back(arena.add(bytes.data(), bytes.size()));
  }
  const std::string big(10000, 'z');  // bigger than a chunk: a chunk of its own
  pieces.push_back(arena.add(big.data(), big.size()));
  EXPECT_EQ(arena.chunksHeld(), 7u);  // 3000 + 3000 > 4096: one payload a chunk
  for (int i = 0; i < 6; ++i) EXPECT_EQ(std::string(pieces[size_t(i)].data(), 3000), std::string(3000, char('a' + i)));
  EXPECT_EQ(std::string(pieces[6].data(), pieces[6].size()), big);
  pieces[0].reset();
  pieces[1] = PayloadArena::Piece();
  EXPECT_EQ(arena.chunksHeld(), 5u);
  pieces.clear();
  EXPECT_EQ(arena.chunksHeld(), 1u);  // the last chunk still takes payloads
  const std::string again(10, 'q');
  PayloadArena::Piece p = arena.add(again.data(), again.size());
  EXPECT_EQ(std::string(p.data(), p.size()), again);
}

TEST(PayloadArena, ConcurrentAddsKeepEveryPayloadIntact) {
  PayloadArena arena(64 << 10);
  constexpr int kThreads = 4, kEach = 200;
  std::vector<std::vector<PayloadArena::Piece>> pieces(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < kEach; ++i) {
        const std::string bytes(size_t(100 + 37 * i % 3000), char(t * kEach + i));
        pieces[size_t(t)].push_back(arena.add(bytes.data(), bytes.size()));
      }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t)
    for (int i = 0; i < kEach; ++i) {
      const PayloadArena::Piece& p = pieces[size_t(t)][size_t(i)];
      ASSERT_EQ(std::string(p.data(), p.size()), std::string(size_t(100 + 37 * i % 3000), char(t * kEach + i)));
    }
}
