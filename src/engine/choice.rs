//! One definition per named choice (model, mobility, backend, coefficient set, overlaps): each enum lists
//! its values once, with the user-facing name and a few words on each; parsing, display, the
//! engine's "unknown ..." error, the script layer's "did you mean" and the `:help` check all read
//! that one table.

use super::error::{EngineError, Result};

/// One value of a choice: the value, its name, and what it means.
#[derive(Debug, Clone, Copy)]
pub struct Choice<T: 'static> {
    /// The value.
    pub value: T,
    /// Its user-facing name.
    pub name: &'static str,
    /// A few words on it ("spheres and springs, default").
    pub about: &'static str,
}

/// A set of named values.
pub trait Named: Copy + PartialEq + 'static {
    /// What the choice is called in messages ("model").
    const KIND: &'static str;
    /// Every value, in the order messages list them.
    const CHOICES: &'static [Choice<Self>];
}

/// The name of `value`.
pub fn name<T: Named>(value: T) -> &'static str {
    T::CHOICES
        .iter()
        .find(|c| c.value == value)
        .map_or("?", |c| c.name)
}

/// Every name, in order.
pub fn names<T: Named>() -> Vec<&'static str> {
    T::CHOICES.iter().map(|c| c.name).collect()
}

/// The value called `given`, or [`EngineError::UnknownChoice`] listing the valid ones.
pub fn parse<T: Named>(given: &str) -> Result<T> {
    T::CHOICES
        .iter()
        .find(|c| c.name == given)
        .map(|c| c.value)
        .ok_or_else(|| EngineError::UnknownChoice {
            kind: T::KIND,
            given: given.to_string(),
            closest: closest(given, &names::<T>()),
            valid: T::CHOICES.iter().map(|c| (c.name, c.about)).collect(),
        })
}

/// The closest of `options` to `word` by edit distance, if reasonably close (for "did you mean").
pub fn closest<'a>(word: &str, options: &[&'a str]) -> Option<&'a str> {
    options
        .iter()
        .map(|o| (edit_distance(word, o), *o))
        .filter(|(d, o)| *d <= (o.len() / 2).max(1))
        .min_by_key(|(d, _)| *d)
        .map(|(_, o)| o)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// `T::parse(name)` and `t.name()` as inherent methods of a [`Named`] type, read from its table.
macro_rules! inherent_names {
    ($t:ty) => {
        impl $t {
            /// Parse a user-facing name.
            pub fn parse(name: &str) -> $crate::engine::error::Result<Self> {
                $crate::engine::choice::parse(name)
            }

            /// The user-facing name.
            pub fn name(self) -> &'static str {
                $crate::engine::choice::name(self)
            }
        }
    };
}
pub(crate) use inherent_names;
