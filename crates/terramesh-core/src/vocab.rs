//! One vocabulary: the names users type for each setting.
//!
//! Every setting with a fixed set of values (a smoother, a variogram model, a drift, a
//! sampling kernel, an export format, ...) is one library enum that implements [`Named`]
//! through [`named_enum!`](crate::named_enum). That gives it `FromStr` (case-insensitive,
//! with aliases), `Display` and serde as the same lower-case names, so the library, the
//! project file, the command line and Python all read and write one spelling, and an unknown
//! name is an [`UnknownName`] error that lists what is accepted.
//!
//! ```
//! use terramesh_core::vocab::Named;
//!
//! #[derive(Clone, Copy, Debug, PartialEq, Eq)]
//! pub enum Colour { Red, Green }
//! terramesh_core::named_enum!(Colour, "colour", [Colour::Red => "red" | "r", Colour::Green => "green"]);
//!
//! assert_eq!("RED".parse::<Colour>()?, Colour::Red);
//! assert_eq!("r".parse::<Colour>()?, Colour::Red);
//! assert_eq!(Colour::Green.to_string(), "green");
//! let e = "blue".parse::<Colour>().unwrap_err();
//! assert_eq!(e.to_string(), "unknown colour \"blue\": expected red or green");
//! assert_eq!(Colour::names(), ["red", "green"]);
//! # Ok::<(), terramesh_core::vocab::UnknownName>(())
//! ```

#[doc(hidden)]
pub use serde as __serde;

/// A setting with a fixed set of named values.
pub trait Named: Copy + Sized + 'static {
    /// What the setting is, for messages (`"smoother"`).
    const WHAT: &'static str;
    /// Every value, in the order help texts list them.
    const ALL: &'static [Self];

    /// The name users type and files store.
    fn name(self) -> &'static str;

    /// Other accepted spellings (never written).
    fn aliases(self) -> &'static [&'static str] {
        &[]
    }

    /// Every name, in the order of [`Named::ALL`].
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|v| v.name()).collect()
    }

    /// Parses a name or an alias, ignoring case and surrounding blanks.
    fn parse_name(s: &str) -> Result<Self, UnknownName> {
        let t = s.trim();
        Self::ALL
            .iter()
            .copied()
            .find(|v| {
                v.name().eq_ignore_ascii_case(t)
                    || v.aliases().iter().any(|a| a.eq_ignore_ascii_case(t))
            })
            .ok_or_else(|| UnknownName {
                what: Self::WHAT,
                given: s.to_string(),
                expected: Self::names(),
            })
    }
}

/// A name that is not one of a setting's values.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} \"{given}\": expected {}", one_of(expected))]
pub struct UnknownName {
    /// The setting (`"smoother"`).
    pub what: &'static str,
    /// What was given.
    pub given: String,
    /// The accepted names.
    pub expected: Vec<&'static str>,
}

/// `a, b or c`.
pub fn one_of(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => (*one).to_string(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

/// Implements [`Named`], `FromStr`, `Display`, `Serialize` and `Deserialize` for a field-less
/// enum from one table of names: `named_enum!(Type, "what", [Type::A => "a" | "alias", ...])`.
/// See the [module](crate::vocab) for an example.
#[macro_export]
macro_rules! named_enum {
    ($t:ty, $what:literal, [$($v:path => $name:literal $(| $alias:literal)*),+ $(,)?]) => {
        impl $crate::vocab::Named for $t {
            const WHAT: &'static str = $what;
            const ALL: &'static [Self] = &[$($v),+];
            fn name(self) -> &'static str {
                match self { $($v => $name),+ }
            }
            fn aliases(self) -> &'static [&'static str] {
                match self { $($v => &[$($alias),*]),+ }
            }
        }
        impl ::core::str::FromStr for $t {
            type Err = $crate::vocab::UnknownName;
            fn from_str(s: &str) -> ::core::result::Result<Self, Self::Err> {
                <$t as $crate::vocab::Named>::parse_name(s)
            }
        }
        impl ::core::fmt::Display for $t {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                f.write_str($crate::vocab::Named::name(*self))
            }
        }
        impl $crate::vocab::__serde::Serialize for $t {
            fn serialize<S: $crate::vocab::__serde::Serializer>(
                &self,
                s: S,
            ) -> ::core::result::Result<S::Ok, S::Error> {
                s.serialize_str($crate::vocab::Named::name(*self))
            }
        }
        impl<'de> $crate::vocab::__serde::Deserialize<'de> for $t {
            fn deserialize<D: $crate::vocab::__serde::Deserializer<'de>>(
                d: D,
            ) -> ::core::result::Result<Self, D::Error> {
                let s = <::std::string::String as $crate::vocab::__serde::Deserialize>::deserialize(d)?;
                <$t as $crate::vocab::Named>::parse_name(&s)
                    .map_err(<D::Error as $crate::vocab::__serde::de::Error>::custom)
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    enum Kind {
        A,
        B,
    }
    crate::named_enum!(Kind, "kind", [Kind::A => "alpha" | "a", Kind::B => "beta"]);

    #[test]
    fn names_round_trip_and_unknown_names_list_the_choices() {
        for k in Kind::ALL {
            assert_eq!(k.to_string().parse::<Kind>(), Ok(*k));
        }
        assert_eq!(" A ".parse::<Kind>(), Ok(Kind::A));
        let e = "gamma".parse::<Kind>().unwrap_err();
        assert_eq!(e.expected, ["alpha", "beta"]);
        assert!(e.to_string().contains("alpha or beta"), "{e}");
        assert_eq!(one_of(&["x"]), "x");
        assert_eq!(one_of(&["x", "y", "z"]), "x, y or z");
    }

    #[test]
    fn serde_uses_the_names() {
        #[derive(serde::Serialize, serde::Deserialize, PartialEq, Debug)]
        struct S {
            k: Kind,
        }
        let j = serde_json::to_string(&S { k: Kind::B }).unwrap();
        assert_eq!(j, r#"{"k":"beta"}"#);
        assert_eq!(
            serde_json::from_str::<S>(r#"{"k":"Alpha"}"#).unwrap(),
            S { k: Kind::A }
        );
        let e = serde_json::from_str::<S>(r#"{"k":"x"}"#).unwrap_err();
        assert!(e.to_string().contains("unknown kind \"x\""), "{e}");
    }
}
