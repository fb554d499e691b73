//! The gesture table: every gesture the head knows is one row here.
//!
//! A row names the gesture's command word, the axis it moves, its
//! [`Shape`] (how it moves: see [`crate::behaviour::gesture`]), how many
//! cycles it may have, and its built-in defaults. Everything else derives
//! from the table: the enum [`GestureKind`] and [`GestureKind::ALL`], the
//! console's parser and `help`, the checks of the behaviour configuration
//! and of a request, the settings record, the log of the frame task, the
//! trace scripts and the panic proof. A new row either works everywhere or
//! fails to compile: its word must not be one the console already has, its
//! defaults must validate against the built-in driver
//! ([`BehaviourConfig::DEFAULT`](crate::behaviour::BehaviourConfig::DEFAULT)
//! is checked at compile time), a posture ([`Shape::Lean`]) has exactly one
//! cycle. Adding one is a recipe in the developer guide.
//!
//! ```
//! use idle_head_core::gestures::{GestureKind, Shape};
//! use idle_head_core::Axis;
//!
//! let nod = GestureKind::Nod.row();
//! assert_eq!((nod.name, nod.axis, nod.shape), ("nod", Axis::Pitch, Shape::Dip));
//! assert_eq!(GestureKind::from_name(b"SHAKE"), Some(GestureKind::Shake));
//! assert!(GestureKind::ALL.iter().all(|k| GestureKind::from_name(k.name().as_bytes()) == Some(*k)));
//! ```

use const_format::concatcp;
use const_format::utils::str_eq;

use crate::axis::Axis;
use crate::units::{Angle, MilliHertz, Percent};

pub use crate::behaviour::shape::Shape;

/// Declares [`GestureKind`] and its rows from the table below.
macro_rules! gestures {
    ($(
        $(#[doc = $doc:literal])*
        $kind:ident {
            name: $name:literal,
            axis: $axis:expr,
            shape: $shape:expr,
            max_cycles: $max:expr,
            defaults: $defaults:expr,
            settings: $settings:expr $(,)?
        }
    ),+ $(,)?) => {
        /// The gestures, one per row of the [table](self).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub enum GestureKind {
            $($(#[doc = $doc])* $kind,)+
        }

        impl GestureKind {
            /// Every gesture, in the table's order.
            pub const ALL: [Self; [$(stringify!($kind)),+].len()] = [$(Self::$kind),+];

            /// The command words, each after a space (` nod shake tilt`):
            /// for `help`.
            pub const WORDS: &'static str = concatcp!($(" ", $name),+);

            /// The gesture's row.
            #[must_use]
            pub const fn row(self) -> &'static Gesture {
                match self {
                    $(Self::$kind => {
                        const ROW: Gesture = Gesture {
                            kind: GestureKind::$kind,
                            name: $name,
                            axis: $axis,
                            shape: $shape,
                            max_cycles: $max,
                            defaults: $defaults,
                            settings: $settings,
                            fields: Fields {
                                amplitude: concatcp!($name, ".amplitude"),
                                intensity: concatcp!($name, ".intensity"),
                                duration: concatcp!($name, " duration"),
                                cycles: concatcp!($name, ".cycles"),
                                slow: concatcp!($name, ".slow"),
                                brisk: concatcp!($name, ".brisk"),
                            },
                        };
                        &ROW
                    })+
                }
            }
        }
    };
}

/// Most cycles of one gesture.
pub const MAX_CYCLES: u8 = 32;

// The table. A new gesture is a new row (the recipe: "Adding a gesture" in
// the developer guide). `defaults`: the first peak at 50 % intensity (a
// default amplitude scales with intensity and cycles, see
// `behaviour::gesture`), the cycles when not asked for, the cycle frequency
// at 0 % and at 100 % intensity (a posture's "cycle" is its whole
// duration), the intensity when not asked for. `settings`: the first of
// the five ids its defaults take in the stored settings; ids are never
// reused, so a new gesture takes a new block (the next free one is named
// in `settings/fields.rs`).
gestures! {
    // ANCHOR: nod
    /// Nodding "yes" on the pitch axis.
    Nod {
        name: "nod",
        axis: Axis::Pitch,
        shape: Shape::Dip,
        max_cycles: MAX_CYCLES,
        defaults: GestureDefaults {
            amplitude: Angle::from_degrees(6),
            cycles: 2,
            slow: MilliHertz(1500),
            brisk: MilliHertz(3500),
            intensity: Percent::HALF,
        },
        settings: 22,
    },
    // ANCHOR_END: nod
    /// Shaking "no" on the yaw axis.
    Shake {
        name: "shake",
        axis: Axis::Yaw,
        shape: Shape::Swing,
        max_cycles: MAX_CYCLES,
        defaults: GestureDefaults {
            amplitude: Angle::from_degrees(8),
            cycles: 3,
            slow: MilliHertz(1200),
            brisk: MilliHertz(2500),
            intensity: Percent::HALF,
        },
        settings: 27,
    },
    /// Tilting the head to one side on the roll axis.
    Tilt {
        name: "tilt",
        axis: Axis::Roll,
        shape: Shape::Lean,
        max_cycles: 1,
        defaults: GestureDefaults {
            amplitude: Angle::from_degrees(10),
            cycles: 1,
            // 2.5 s … 1 s.
            slow: MilliHertz(400),
            brisk: MilliHertz(1000),
            intensity: Percent::HALF,
        },
        settings: 32,
    },
}

/// How many ids a gesture's defaults take in the stored settings: its
/// amplitude, cycles, slow and brisk frequencies and intensity, in this
/// order from [`Gesture::settings`].
pub const SETTINGS_IDS: u8 = 5;

/// One row of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Gesture {
    /// The gesture.
    pub kind: GestureKind,
    /// Its command word, lower case (`nod`).
    pub name: &'static str,
    /// The axis it moves.
    pub axis: Axis,
    /// How it moves.
    pub shape: Shape,
    /// Most cycles a request may ask for (a posture: 1).
    pub max_cycles: u8,
    /// The built-in defaults ([`BehaviourConfig::DEFAULT`](crate::behaviour::BehaviourConfig::DEFAULT)).
    pub defaults: GestureDefaults,
    /// The first of the [`SETTINGS_IDS`] ids its defaults take in the
    /// stored settings (`crate::settings::FIELDS`): a block no other field
    /// or gesture uses, never reused once a firmware has saved it. A new
    /// gesture takes the next free block (the settings table says which).
    pub settings: u8,
    /// The names its fields have in errors and in the settings, made from
    /// `name`.
    pub fields: Fields,
}

/// The names of a gesture's fields in error messages (`nod duration`,
/// `nod.cycles`, ...), made from its command word at compile time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Fields {
    /// The configured default amplitude (`nod.amplitude`).
    pub amplitude: &'static str,
    /// The configured default intensity (`nod.intensity`).
    pub intensity: &'static str,
    /// A request's duration (`nod duration`).
    pub duration: &'static str,
    /// The configured default cycles (`nod.cycles`).
    pub cycles: &'static str,
    /// The configured frequency at 0 % (`nod.slow`).
    pub slow: &'static str,
    /// The configured frequency at 100 % (`nod.brisk`).
    pub brisk: &'static str,
}

/// The defaults of one gesture; see [`behaviour::gesture`](crate::behaviour::gesture)
/// for what they shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GestureDefaults {
    /// Peak amplitude of the first cycle at 50 % intensity.
    pub amplitude: Angle,
    /// Cycles when not asked for (a posture always has one).
    pub cycles: u8,
    /// Cycle frequency at 0 % intensity.
    pub slow: MilliHertz,
    /// Cycle frequency at 100 % intensity.
    pub brisk: MilliHertz,
    /// Intensity when not asked for.
    pub intensity: Percent,
}

impl GestureKind {
    /// How many gestures there are.
    pub const COUNT: usize = Self::ALL.len();

    /// The built-in defaults of every gesture, in the order of [`ALL`](Self::ALL).
    pub const DEFAULTS: [GestureDefaults; Self::COUNT] = {
        let mut defaults = [Self::ALL[0].row().defaults; Self::COUNT];
        let mut i = 0;
        while i < Self::COUNT {
            defaults[i] = Self::ALL[i].row().defaults;
            i += 1;
        }
        defaults
    };

    /// The position of the gesture in [`ALL`](Self::ALL).
    #[must_use]
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The command word (`nod`, `shake`, `tilt`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        self.row().name
    }

    /// The axis the gesture moves.
    #[must_use]
    pub const fn axis(self) -> Axis {
        self.row().axis
    }

    /// How the gesture moves.
    #[must_use]
    pub const fn shape(self) -> Shape {
        self.row().shape
    }

    /// The gesture whose command word is `word`, ignoring ASCII case.
    #[must_use]
    pub fn from_name(word: &[u8]) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|kind| kind.name().as_bytes().eq_ignore_ascii_case(word))
    }
}

// The table's own rules, checked when the crate compiles: each word lower
// case ASCII letters, and no two alike; the cycles within what the shape
// and `MAX_CYCLES` allow.
const _: () = {
    let mut i = 0;
    while i < GestureKind::COUNT {
        let row = GestureKind::ALL[i].row();
        let word = row.name.as_bytes();
        assert!(!word.is_empty(), "a gesture has a command word");
        let mut b = 0;
        while b < word.len() {
            assert!(
                word[b].is_ascii_lowercase(),
                "a command word is lower case ASCII letters"
            );
            b += 1;
        }
        assert!(
            row.max_cycles >= 1 && row.max_cycles <= MAX_CYCLES,
            "a gesture has 1..=MAX_CYCLES cycles"
        );
        assert!(
            row.max_cycles == 1 || row.shape.has_cycles(),
            "a posture (Shape::Lean) has exactly one cycle: max_cycles: 1"
        );
        let mut j = 0;
        while j < i {
            assert!(
                !str_eq(GestureKind::ALL[j].name(), row.name),
                "two gestures with one word"
            );
            j += 1;
        }
        i += 1;
    }
};
