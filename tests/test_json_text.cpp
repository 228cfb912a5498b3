// tool/json_text.hpp writes the bytes nlohmann's dump(2) writes: objects of random members
// (doubles of every kind, NaN and infinities, integers), alone and as arrays in a document.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "tool/json_text.hpp"

namespace {

using ranging::tool::json_array_text;
using ranging::tool::json_splice;
using ranging::tool::JsonArrayText;
using ranging::tool::JsonObjectText;

// A member: an integer or a double.
struct Member {
  std::string key;
  bool integer = false;
  long long i = 0;
  double d = 0;
};
using Object = std::vector<Member>;  // keys in increasing order

double random_double(std::mt19937_64& rng) {
  static const double specials[] = {0.0,
                                    -0.0,
                                    1.0,
                                    -3.0,
                                    0.5,
                                    1e-5,
                                    1e-4,
                                    123456789012345.0,
                                    1234567890123456.0,
                                    1e16,
                                    1e21,
                                    1e22,
                                    2.5e-300,
                                    std::numeric_limits<double>::denorm_min(),
                                    std::numeric_limits<double>::min(),
                                    std::numeric_limits<double>::max(),
                                    std::numeric_limits<double>::lowest(),
                                    std::numeric_limits<double>::quiet_NaN(),
                                    std::numeric_limits<double>::infinity(),
                                    -std::numeric_limits<double>::infinity()};
  switch (rng() % 4) {
    case 0:
      return specials[rng() % std::size(specials)];
    case 1:
      return std::bit_cast<double>(rng());  // any bit pattern, NaNs included
    case 2:
      return std::ldexp(static_cast<double>(rng() % 2000001) - 1e6, static_cast<int>(rng() % 80) - 60);
    default:
      return std::uniform_real_distribution<double>(-1, 1)(rng);
  }
}

Object random_object(std::mt19937_64& rng) {
  static const char* keys[] = {"a", "arrival_s", "code", "distance_m", "error_m", "pearson_code", "rho", "tof_s", "u"};
  Object o;
  for (const char* k : keys) {
    if (rng() % 3 == 0) continue;
    Member m{k};
    m.integer = rng() % 3 == 0;
    if (m.integer) {
      m.i = static_cast<long long>(rng() >> (rng() % 64));
      if (rng() % 2) m.i = -m.i;
    } else {
      m.d = random_double(rng);
    }
    o.push_back(m);
  }
  return o;
}

nlohmann::json to_json(const Object& o) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& m : o) {
    if (m.integer) {
      j[m.key] = m.i;
    } else {
      j[m.key] = m.d;
    }
  }
  return j;
}

void write(JsonObjectText& t, const Object& o) {
  for (const auto& m : o) {
    if (m.integer) {
      t.integer(m.key, m.i);
    } else {
      t.number(m.key, m.d);
    }
  }
}

TEST(JsonText, AnObjectIsDumpsText) {
  std::mt19937_64 rng(7);
  for (int n = 0; n < 20000; ++n) {
    const Object o = random_object(rng);
    std::string text;
    JsonObjectText t(text, 0);
    write(t, o);
    t.finish();
    ASSERT_EQ(text, to_json(o).dump(2)) << "object " << n;
  }
}

TEST(JsonText, AnArrayInADocumentIsDumpsText) {
  std::mt19937_64 rng(11);
  for (std::size_t count : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{513}, std::size_t{1500}}) {
    std::vector<Object> v;
    for (std::size_t i = 0; i < count; ++i) v.push_back(random_object(rng));
    nlohmann::json whole = {{"first", 1}, {"last", "x"}};
    whole["list"] = nlohmann::json::array();
    for (const auto& o : v) whole["list"].push_back(to_json(o));
    nlohmann::json doc = {{"first", 1}, {"last", "x"}, {"list", "\x01"}};
    for (int jobs : {1, 3}) {
      std::string text = doc.dump(2);
      const std::string mark = "\"\\u0001\"";
      const std::size_t at = text.find(mark);
      ASSERT_NE(at, std::string::npos);
      const JsonArrayText a = json_array_text(v, write, 1, jobs);
      std::ostringstream spliced;  // the same document written piece by piece
      json_splice(spliced, text, {{mark, &a}});
      text.replace(at, mark.size(), a.str());
      EXPECT_EQ(text, whole.dump(2)) << count << " elements, jobs " << jobs;
      EXPECT_EQ(spliced.str(), text) << count << " elements, jobs " << jobs;
    }
    // one level deeper: the array as a member of an object that is itself a member
    nlohmann::json inner = {{"outer", {{"list", whole["list"]}}}};
    std::string text = nlohmann::json({{"outer", {{"list", "\x01"}}}}).dump(2);
    text.replace(text.find("\"\\u0001\""), 8, json_array_text(v, write, 2, 2).str());
    EXPECT_EQ(text, inner.dump(2)) << count << " elements at depth 2";
  }
}

TEST(JsonText, SpliceWritesEveryArrayInItsPlace) {
  // two arrays, their markers in the document in the order opposite to the list's
  std::mt19937_64 rng(13);
  std::vector<Object> a, b;
  for (int i = 0; i < 600; ++i) a.push_back(random_object(rng));
  for (int i = 0; i < 3; ++i) b.push_back(random_object(rng));
  nlohmann::json whole = {{"alpha", nlohmann::json::array()}, {"beta", nlohmann::json::array()}, {"mid", 2}};
  for (const auto& o : a) whole["alpha"].push_back(to_json(o));
  for (const auto& o : b) whole["beta"].push_back(to_json(o));
  const std::string doc = nlohmann::json({{"alpha", "\x01" "a"}, {"beta", "\x01" "b"}, {"mid", 2}}).dump(2);
  const JsonArrayText ta = json_array_text(a, write, 1, 2), tb = json_array_text(b, write, 1, 2);
  std::ostringstream os;
  json_splice(os, doc, {{"\"\\u0001b\"", &tb}, {"\"\\u0001a\"", &ta}});
  EXPECT_EQ(os.str(), whole.dump(2));
  std::ostringstream none;
  EXPECT_THROW(json_splice(none, doc, {{"\"\\u0001c\"", &ta}}), std::logic_error);
}

TEST(JsonText, RefusesKeysOutOfOrderOrNeedingEscapes) {
  std::string text;
  JsonObjectText t(text, 0);
  t.number("b", 1.0);
  EXPECT_THROW(t.number("a", 1.0), std::logic_error);
  EXPECT_THROW(t.integer("b", 1), std::logic_error);  // a repeated key
  std::string other;
  JsonObjectText u(other, 0);
  EXPECT_THROW(u.number("a\"b", 1.0), std::logic_error);
  EXPECT_THROW(u.number("a\nb", 1.0), std::logic_error);
}

}  // namespace
