// Exception-message expectations for tests.
//
// The library's errors carry precise messages and the tests assert them
// exactly. Instead of a try/catch per assertion:
//
//   EXPECT_THROW_MESSAGE(options.Validate(), InvalidInputError,
//                        "time_step = -1 is invalid: must be > 0");
//   EXPECT_EQ(MessageOf<InvalidInputError>([&] { ReadObj(path); }), "cannot open '" + path + "'");
//
// EXPECT_THROW_MESSAGE(statement, E, expected) passes when the statement
// throws an E (or a class derived from it) whose what() equals `expected`
// exactly; on failure it prints the expected and the actual message, or says
// that nothing was thrown, or names the other exception type that was thrown
// and its message. ASSERT_THROW_MESSAGE is the fatal form.
//
// MessageOf<E>(call) returns the message of the E that call() throws, for
// tests that compute or post-process the expected text; when call() throws
// nothing or something else it returns a description in parentheses, which
// no library message equals, so EXPECT_EQ fails and prints it.
#pragma once

#include <gtest/gtest.h>

#include <cxxabi.h>

#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <typeinfo>
#include <utility>

namespace diffpd::testing {

// A readable (demangled) name of a type.
inline std::string TypeName(const std::type_info& type) {
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> name(abi::__cxa_demangle(type.name(), nullptr, nullptr, &status), std::free);
  return status == 0 && name ? std::string(name.get()) : std::string(type.name());
}

// What call() threw: whether it was an E, and its message or a description.
struct ThrownMessage {
  bool expected_type = false;  // an E was thrown
  std::string text;            // E's what(), or a description in parentheses
};

template <class E, class Call>
ThrownMessage CatchMessage(Call&& call) {
  try {
    try {
      std::forward<Call>(call)();
    } catch (const E& error) {
      return {true, error.what()};
    }
  } catch (const std::exception& error) {  // (nested: E may itself be std::exception)
    return {false, "(" + TypeName(typeid(error)) + " thrown instead of " + TypeName(typeid(E)) + ": \"" + error.what() +
                       "\")"};
  } catch (...) {
    return {false, "(an exception that is not a std::exception thrown instead of " + TypeName(typeid(E)) + ")"};
  }
  return {false, "(no exception thrown; expected " + TypeName(typeid(E)) + ")"};
}

template <class E, class Call>
std::string MessageOf(Call&& call) {
  return CatchMessage<E>(std::forward<Call>(call)).text;
}

// Success when call() throws an E whose what() is exactly `expected`.
template <class E, class Call>
::testing::AssertionResult ThrowsWithMessage(Call&& call, const std::string& expected) {
  const ThrownMessage thrown = CatchMessage<E>(std::forward<Call>(call));
  if (thrown.expected_type && thrown.text == expected) return ::testing::AssertionSuccess();
  ::testing::AssertionResult failure = ::testing::AssertionFailure();
  failure << "\n  expected " << TypeName(typeid(E)) << " with message\n    \"" << expected << "\"\n  ";
  if (thrown.expected_type) {
    failure << "got the message\n    \"" << thrown.text << "\"";
  } else {
    failure << "got " << thrown.text;
  }
  return failure;
}

}  // namespace diffpd::testing

#define EXPECT_THROW_MESSAGE(statement, exception_type, expected) \
  EXPECT_TRUE(::diffpd::testing::ThrowsWithMessage<exception_type>([&] { statement; }, expected))
#define ASSERT_THROW_MESSAGE(statement, exception_type, expected) \
  ASSERT_TRUE(::diffpd::testing::ThrowsWithMessage<exception_type>([&] { statement; }, expected))
