#include "msfem/cases/units.hpp"

#include <gtest/gtest.h>

#include <string>

#include "msfem/cases/errors.hpp"

namespace msfem::cases {
namespace {

TEST(Units, ParsesTheThreeNames) {
  EXPECT_EQ(parse_length_unit("m"), LengthUnit::metre);
  EXPECT_EQ(parse_length_unit("cm"), LengthUnit::centimetre);
  EXPECT_EQ(parse_length_unit("mm"), LengthUnit::millimetre);
}

TEST(Units, ToStringIsTheInverseOfParse) {
  for (LengthUnit unit : {LengthUnit::metre, LengthUnit::centimetre, LengthUnit::millimetre})
    EXPECT_EQ(parse_length_unit(to_string(unit)), unit);
  EXPECT_EQ(to_string(LengthUnit::millimetre), "mm");
}

TEST(Units, MetresPerUnit) {
  EXPECT_EQ(metres_per(LengthUnit::metre), 1.0);
  EXPECT_EQ(metres_per(LengthUnit::centimetre), 1e-2);
  EXPECT_EQ(metres_per(LengthUnit::millimetre), 1e-3);
}

TEST(Units, UnknownNameIsAnInputErrorNamingItAndTheAllowedOnes) {
  // Case matters ("M" is not "m") and there are no long names: the case files use the short ones.
  for (const char* bad : {"km", "M", "metre", "", "mm "}) {
    try {
      parse_length_unit(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(std::string("'") + bad + "'"), std::string::npos) << message;
      EXPECT_NE(message.find("(m, cm, mm)"), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

}  // namespace
}  // namespace msfem::cases
