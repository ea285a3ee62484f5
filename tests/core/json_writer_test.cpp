// The JSON writer the render report is built with (core/json_writer.h).
#include "core/json_writer.h"
#include "core/text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace dpoint {
namespace {

TEST(JsonWriter, keepsTheOrderEscapesStringsAndWritesNumbersShortest) {
  JsonObject inner;
  inner.add("b", JsonValue::integer(2)).add("a", JsonValue::boolean(false));
  JsonObject o;
  o.add("z \"quoted\"\n", JsonValue::string("back\\slash\ttab"));
  o.add("n", JsonValue::number(0.1)).add("inf", JsonValue::number(HUGE_VAL)).add("nan", JsonValue::number(std::nan("")));
  o.add("list", JsonValue::numbers(std::vector<double>{1.0, 2.5, 1e-300})).add("empty", JsonValue::numbers({}));
  o.add("inner", inner).add("none", JsonValue::null()).add("nothing", JsonObject());
  EXPECT_EQ(o.block(),
            "{\n"
            "  \"z \\\"quoted\\\"\\u000a\": \"back\\\\slash\\u0009tab\",\n"
            "  \"n\": 0.1,\n"
            "  \"inf\": null,\n"
            "  \"nan\": null,\n"
            "  \"list\": [1, 2.5, 1e-300],\n"
            "  \"empty\": [],\n"
            "  \"inner\": {\"b\": 2, \"a\": false},\n"
            "  \"none\": null,\n"
            "  \"nothing\": {}\n"
            "}\n");
  EXPECT_EQ(inner.line(), "{\"b\": 2, \"a\": false}");
  EXPECT_EQ(JsonValue::integer(18446744073709551615ull).text(), "18446744073709551615");
}

// JSON is UTF-8: a byte that is not (a file name's, a header's text) is the replacement character,
// not the raw byte that made the whole document unreadable (a review finding, 2026-12-02); UTF-8
// letters stay as they are.
TEST(JsonWriter, stringsAreUtf8WhateverBytesTheyHold) {
  EXPECT_EQ(jsonString("H\xc3\xb6he \xe9tendu\xff \xe2\x82"), "\"H\xc3\xb6he \\ufffdtendu\\ufffd \\ufffd\\ufffd\"");
  EXPECT_EQ(jsonString("\xf0\x9f\x98\x80\x01"), "\"\xf0\x9f\x98\x80\\u0001\"");
  // Well-formed in shape but not UTF-8 (a second review's finding): a surrogate, overlong forms, a
  // code point past U+10FFFF. Each byte is one replacement character.
  for (const std::string bad : {"\xed\xa0\x80", "\xe0\x80\x80", "\xf0\x80\x80\x80", "\xf4\x90\x80\x80"})
    EXPECT_EQ(jsonString(bad).find_first_of("\x80\xa0\x90"), std::string::npos) << jsonString(bad);
  EXPECT_EQ(jsonString("\xed\x9f\xbf\xf4\x8f\xbf\xbf"), "\"\xed\x9f\xbf\xf4\x8f\xbf\xbf\"");  // U+D7FF, U+10FFFF
  // XML refuses U+FFFE and U+FFFF: not text a header or an E57 file carries.
  EXPECT_EQ(firstNonTextByte("ab\xef\xbf\xbe"), 2u);
  EXPECT_EQ(firstNonTextByte("ab\xef\xbf\xbd"), std::string::npos);  // U+FFFD is
}

}  // namespace
}  // namespace dpoint
