// The exception-message expectations: an exact message of the expected type
// passes; a different message, another exception type or no exception fail
// with a message that shows what was expected and what happened.
#include "util/expect_message.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "diffpd/error.h"

namespace diffpd::testing {
namespace {

void Throw(const std::string& message) { throw InvalidInputError(message); }

TEST(ExpectMessageTest, PassesOnTheExactMessageOfTheExpectedType) {
  EXPECT_TRUE(ThrowsWithMessage<InvalidInputError>([] { Throw("x = -1 is invalid: must be > 0"); },
                                                   "x = -1 is invalid: must be > 0"));
  // A base class of the thrown type matches too.
  EXPECT_TRUE(ThrowsWithMessage<std::invalid_argument>([] { Throw("m"); }, "m"));
  EXPECT_THROW_MESSAGE(Throw("m"), InvalidInputError, "m");
  ASSERT_THROW_MESSAGE(Throw(std::string("a, b")), InvalidInputError, "a, b");
  EXPECT_EQ(MessageOf<InvalidInputError>([] { Throw("exact text"); }), "exact text");
}

TEST(ExpectMessageTest, AnotherMessageFailsAndShowsBoth) {
  const ::testing::AssertionResult r =
      ThrowsWithMessage<InvalidInputError>([] { Throw("x = -1 is invalid"); }, "x = -2 is invalid");
  EXPECT_FALSE(r);
  EXPECT_EQ(std::string(r.message()),
            "\n  expected diffpd::InvalidInputError with message\n    \"x = -2 is invalid\"\n"
            "  got the message\n    \"x = -1 is invalid\"");
  // A prefix or an extension of the message is another message.
  EXPECT_FALSE(ThrowsWithMessage<InvalidInputError>([] { Throw("abc"); }, "ab"));
  EXPECT_FALSE(ThrowsWithMessage<InvalidInputError>([] { Throw("ab"); }, "abc"));
}

TEST(ExpectMessageTest, NoExceptionOrAnotherTypeFailsAndSaysSo) {
  const ::testing::AssertionResult none = ThrowsWithMessage<InvalidInputError>([] {}, "m");
  EXPECT_FALSE(none);
  EXPECT_EQ(std::string(none.message()),
            "\n  expected diffpd::InvalidInputError with message\n    \"m\"\n"
            "  got (no exception thrown; expected diffpd::InvalidInputError)");
  const ::testing::AssertionResult other =
      ThrowsWithMessage<InvalidInputError>([] { throw std::runtime_error("m"); }, "m");
  EXPECT_FALSE(other);
  EXPECT_EQ(std::string(other.message()),
            "\n  expected diffpd::InvalidInputError with message\n    \"m\"\n"
            "  got (std::runtime_error thrown instead of diffpd::InvalidInputError: \"m\")");
  EXPECT_FALSE(ThrowsWithMessage<InvalidInputError>([] { throw 3; }, "m"));
  EXPECT_EQ(MessageOf<InvalidInputError>([] {}), "(no exception thrown; expected diffpd::InvalidInputError)");
  EXPECT_EQ(MessageOf<InvalidInputError>([] { throw SolverError(SolverStatus::kNonFinite, "nan"); }),
            "(diffpd::SolverError thrown instead of diffpd::InvalidInputError: \"nan\")");
}

}  // namespace
}  // namespace diffpd::testing
