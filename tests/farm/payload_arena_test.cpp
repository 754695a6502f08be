// The master's payload arena (master/payload_arena.h): pieces hold exactly the bytes added,
// from several threads at once, and a chunk goes back to the system once its pieces are released.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "allocator_tuning.h"
#include "payload_arena.h"

using frep::farm::adviseHugePages;
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

// adviseHugePages is a hint on the whole 2 MiB pages inside a range: any range (empty, short,
// unaligned, heap or mapped) is accepted and its bytes are left as they are.
TEST(PayloadArena, AdviseHugePagesKeepsAnyBufferIntact) {
  adviseHugePages(nullptr, 0);
  std::vector<char> small(100, 'a');
  adviseHugePages(small.data(), small.size());
  EXPECT_EQ(std::string(small.begin(), small.end()), std::string(100, 'a'));
  std::vector<uint32_t> big(3 << 20);  // 12 MiB, an unaligned start
  for (size_t i = 0; i < big.size(); ++i) big[i] = uint32_t(i * 2654435761u);
  adviseHugePages(reinterpret_cast<char*>(big.data()) + 3, big.size() * 4 - 7);
  for (size_t i = 0; i < big.size(); ++i) ASSERT_EQ(big[i], uint32_t(i * 2654435761u));
  std::vector<uint32_t> fresh;
  fresh.reserve(big.size());
  adviseHugePages(fresh.data(), big.size() * 4);  // before its first write, as the merge does
  fresh.assign(big.begin(), big.end());
  EXPECT_EQ(fresh, big);
}
