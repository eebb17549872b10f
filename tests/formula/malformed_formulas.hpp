#pragma once
// Malformed formulas and the column each one's error must point at: the parser's tests and the command tests
// refuse the same list.
#include <cstddef>
#include <string>
#include <vector>

namespace nonsep::formula_testing {

// A malformed formula and the column its error must point at (1-based).
struct Malformed {
  std::string text;
  std::size_t column;
};

// The list drives the parser's tests (test_formula_parser.cpp) and `nonsep validate` (exit 2,
// test_formula_commands.cpp).
inline const std::vector<Malformed> malformed_formulas = {
    {"", 1},                    // empty
    {"   ", 4},                 // blanks only
    {"q0 +", 5},                // ends after an operator
    {"q0 + * q1", 6},           // two operators
    {"* q0", 1},                // starts with an operator
    {"(q0 + 1", 8},             // unclosed parenthesis
    {"q0 + 1)", 7},             // unopened parenthesis
    {"()", 2},                  // empty parentheses
    {"q0 q1", 4},               // two terms without an operator
    {"2q0", 2},                 // number glued to a name
    {"1.5e", 5},                // exponent without digits
    {"1e999", 1},               // overflow
    {"x + q0", 1},              // unknown name
    {"q0 + p0", 6},             // p in V
    {"q01", 1},                 // leading zero in an index
    {"q64", 1},                 // index beyond the dimension limit
    {"sin q0", 5},              // function without parentheses
    {"sin(q0, q1)", 1},         // too many arguments
    {"atan2(q0)", 1},           // too few arguments
    {"foo(q0)", 1},             // unknown function
    {"sin()", 5},               // no argument
    {"pow(q0,)", 8},            // empty argument
    {"q0 ^", 5},                // power without exponent
    {"q0 ^ * 2", 6},            // power then operator
    {"q0 = 1", 4},              // assignment
    {"q0 % 2", 4},              // modulo
    {"q0; system(\"x\")", 3},   // statement separator
    {"\"q0\"", 1},              // quotes
    {"q0 + 'a'", 6},            // single quotes
    {"#include <cstdlib>", 1},  // preprocessor line
    {"q0\n#define X", 3},       // newline then preprocessor
    {"{q0}", 1},                // braces
    {"q0[0]", 3},               // brackets
    {"q0 \\ 2", 4},             // backslash
    {"q0 // comment", 5},       // a C++ comment: '/' then '/'
    {"q0 /* c */", 5},          // a block comment: '/' then '*'
    {"q0 & 1", 4},              // bitwise and
    {"q0 < 1", 4},              // comparison
    {"q0 ? 1 : 2", 4},          // conditional
    {"lambda(q0)", 1},          // a parameter called as a function
    {"sin", 4},                 // a function without call
    {"q0 + \xc3\xa9", 6},       // non-ASCII
    {"std::exp(q0)", 4},        // C++ scope
    {"q0.x", 3},                // member access after an index is a number glued to a name
    {"0x10", 2},                // hexadecimal
    {"1,2", 2},                 // comma outside a call
};

}  // namespace nonsep::formula_testing
