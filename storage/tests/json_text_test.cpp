#include "drapegen/storage/json_text.hpp"

#include <gtest/gtest.h>

namespace drapegen::storage {
namespace {

// A path in another encoding (Latin-1 here) is no reason to fail a command after its work: its invalid byte becomes
// U+FFFD and the text is valid JSON that reads back.
TEST(JsonText, AStringThatIsNotUtf8IsWrittenWithReplacementCharacters) {
  const nlohmann::json j = {{"capture", "/data/caf\xE9/c1"}, {"gap_mm", 1.5}};
  EXPECT_THROW((void)j.dump(2), nlohmann::json::type_error);  // nlohmann's default
  const std::string text = json_text(j);
  const auto back = nlohmann::json::parse(text);
  EXPECT_EQ(back.at("capture").get<std::string>(), "/data/caf\xEF\xBF\xBD/c1");
  EXPECT_EQ(back.at("gap_mm").get<double>(), 1.5);
  EXPECT_EQ(json_text(j, -1).find('\n'), std::string::npos);
}

}  // namespace
}  // namespace drapegen::storage
