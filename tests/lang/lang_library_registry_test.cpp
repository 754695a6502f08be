// The library registry: case-insensitive lookup, sorted listing, re-registration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>

#include "frep/lang/library/library.h"

namespace frep::lang {
namespace {

Expr one(std::vector<Arg>&) { return Expr(1.0); }
Expr two(std::vector<Arg>&) { return Expr(2.0); }

const bool kRegistered = registerAll({
    {"regTestZeta", "S", "zeta", one},
    {"regTestAlpha", "AS", "alpha", one},
});

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

TEST(LangLibraryRegistry, FindsCaseInsensitively) {
  ASSERT_TRUE(kRegistered);
  const LibraryFunction* f = findLibraryFunction("REGTESTALPHA");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->name, "regTestAlpha");
  EXPECT_EQ(f->signature, "AS");
  EXPECT_EQ(findLibraryFunction("regtestzeta")->summary, "zeta");
  EXPECT_EQ(findLibraryFunction("regTestMissing"), nullptr);
}

TEST(LangLibraryRegistry, ListIsSortedByName) {
  const auto& fns = libraryFunctions();
  ASSERT_GE(fns.size(), 2u);
  for (size_t i = 1; i < fns.size(); ++i)
    EXPECT_LE(lower(fns[i - 1].name), lower(fns[i].name)) << fns[i - 1].name << " " << fns[i].name;
}

TEST(LangLibraryRegistry, ReRegistrationReplaces) {
  size_t before = libraryFunctions().size();
  registerLibraryFunction({"RegTestZeta", "SS", "zeta 2", two});
  EXPECT_EQ(libraryFunctions().size(), before);
  const LibraryFunction* f = findLibraryFunction("regTestZeta");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->signature, "SS");
  std::vector<Arg> args;
  EXPECT_TRUE(f->lower(args).isConst(2.0));
}

}  // namespace
}  // namespace frep::lang
