//! The library's named options ([`penumbra::Choice`]) as clap arguments: the names are the
//! possible values, each shown in `--help` with the variant's own documentation.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use penumbra::Choice;

/// The parser of an argument that takes one of `T`'s names.
pub(crate) fn choice<T: Choice + Send + Sync>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(
        T::CHOICES
            .iter()
            .map(|c| PossibleValue::new(c.name()).help(c.summary())),
    )
    .map(|name| T::named(&name).expect("clap admits only the possible values"))
}
