//! A closed set of options a user picks by name: `--method` on the command line, `method=` in
//! Python, a menu in the workbench. The library says what the options are called and what each
//! is; the callers (the command line's parser, Python's arguments, the workbench's menus) turn
//! that into their own form, so that no front end's machinery is written into the library.

/// An option picked by name from a closed set.
pub trait Choice: Copy + 'static {
    /// Every option, in the order lists show them.
    const CHOICES: &'static [Self];

    /// The name a user types (kebab-case).
    fn name(self) -> &'static str;

    /// What the option is, in one paragraph (the variant's documentation).
    fn summary(self) -> &'static str;

    /// The option called `name`.
    fn named(name: &str) -> Option<Self> {
        Self::CHOICES.iter().copied().find(|c| c.name() == name)
    }

    /// The names, in the order of [`Choice::CHOICES`].
    fn names() -> impl Iterator<Item = &'static str> {
        Self::CHOICES.iter().map(|c| c.name())
    }
}

/// Declares an enum of options and its [`Choice`]: each variant with its documentation, which
/// is also its [`Choice::summary`], and the name a user types; `default = Variant;` after the
/// enum implements `Default`. The enum derives `Copy` itself; `ALL` lists its variants in order
/// as an array, and `name` is also an inherent method.
///
/// ```
/// penumbra::choice! {
///     /// How a pie is cut.
///     #[derive(Clone, Copy, Debug, PartialEq)]
///     pub enum Cut {
///         /// Into equal wedges.
///         Wedges = "wedges",
///         /// Into a grid of squares.
///         Squares = "squares",
///     }
/// }
/// use penumbra::Choice;
/// assert_eq!(Cut::named("squares"), Some(Cut::Squares));
/// assert_eq!(Cut::Wedges.summary(), "Into equal wedges.");
/// ```
#[macro_export]
macro_rules! choice {
    (
        $(#[$attr:meta])*
        $vis:vis enum $name:ident {
            $(
                $(#[doc = $doc:literal])*
                $variant:ident = $text:literal
            ),+ $(,)?
        }
        $(default = $default:ident;)?
    ) => {
        $(#[$attr])*
        $vis enum $name {
            $(
                $(#[doc = $doc])*
                $variant,
            )+
        }

        impl $name {
            /// Every option, in order.
            pub const ALL: [$name; [$($name::$variant),+].len()] = [$($name::$variant),+];

            /// The name a user types.
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $text,)+
                }
            }
        }

        $(
            // The variant's `#[default]` would need the macro to tell one variant from the
            // others, which macro_rules cannot; this is that derive written out.
            #[allow(clippy::derivable_impls)]
            impl Default for $name {
                fn default() -> Self {
                    $name::$default
                }
            }
        )?

        impl $crate::Choice for $name {
            const CHOICES: &'static [Self] = &$name::ALL;

            fn name(self) -> &'static str {
                $name::name(self)
            }

            fn summary(self) -> &'static str {
                match self {
                    // Each line of a doc comment starts with the space after `///`: joined,
                    // they read as one paragraph, with one space to trim at the start.
                    $($name::$variant => concat!($($doc),*).trim_ascii_start(),)+
                }
            }
        }
    };
}
