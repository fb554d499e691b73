//! The firmware's log: defmt's macros with the `defmt` feature (every
//! board), nothing without it (the host tests, the project commands), so
//! that the layer runs on the host with no defmt logger. The arguments are
//! still type-checked and count as used either way.

/// A value the log can show: `defmt::Format` with the `defmt` feature,
/// anything without it.
#[cfg(feature = "defmt")]
pub trait Loggable: defmt::Format {}
#[cfg(feature = "defmt")]
impl<T: defmt::Format + ?Sized> Loggable for T {}

/// A value the log can show: `defmt::Format` with the `defmt` feature,
/// anything without it.
#[cfg(not(feature = "defmt"))]
pub trait Loggable {}
#[cfg(not(feature = "defmt"))]
impl<T: ?Sized> Loggable for T {}

/// Defines one level's macro: defmt's, or one that only looks at its
/// arguments (in a closure that never runs: nothing is evaluated).
macro_rules! level {
    ($name:ident, $local:ident, $dollar:tt) => {
        #[cfg(feature = "defmt")]
        macro_rules! $local {
                            ($dollar($dollar t:tt)*) => { defmt::$name!($dollar($dollar t)*) };
                        }
        #[cfg(not(feature = "defmt"))]
        macro_rules! $local {
                            ($dollar fmt:literal $dollar(, $dollar arg:expr)* $dollar(,)?) => {{
                                let _ = || {
                                    $dollar(let _ = &$dollar arg;)*
                                };
                            }};
                        }
        // (Under another name first: `warn` alone is also an attribute.)
        pub(crate) use $local as $name;
    };
}

level!(info, info_, $);
level!(warn, warn_, $);
level!(error, error_, $);
