//! The label font (`glyphs`).

use fabkit_designs::glyphs::glyph;

/// Every capital and digit has a glyph of its own: none blank, no two alike.
#[test]
fn capitals_and_digits_are_distinct() {
    let chars: Vec<char> = ('A'..='Z').chain('0'..='9').collect();
    for (i, a) in chars.iter().enumerate() {
        assert_ne!(glyph(*a), [0; 5], "{a}");
        for b in &chars[i + 1..] {
            assert_ne!(glyph(*a), glyph(*b), "{a} and {b}");
        }
    }
}
