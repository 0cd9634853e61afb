//! The finiteness check of a report: a computed value that is ±∞ or NaN stops the run with an
//! error naming it. The check walks a step's record through its `Serialize` implementation, so
//! every number that would reach the JSON is seen; an allowed infinity (ω² of a massless
//! direction) is an absent value (`None`, JSON null) in the record, never a float.

use super::Step;
use serde::Serialize;
use serde::ser;

/// A computed value that is not a finite number: the inputs' scale overflowed double
/// precision somewhere. A run stops with this error (and a non-zero exit) instead of
/// reporting the value.
#[derive(Debug, Clone, PartialEq)]
pub struct NonFiniteResult {
    /// The step that computed it.
    pub analysis: String,
    /// The quantity: its path in the step's record, e.g. `modes[2].effective_mass[0]`.
    pub quantity: String,
    /// The value (±∞ or NaN).
    pub value: f64,
}

impl std::fmt::Display for NonFiniteResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} is {}, not a finite number (the inputs overflow double precision: check the scale of masses, lengths and loads)",
            self.analysis, self.quantity, self.value
        )
    }
}

impl std::error::Error for NonFiniteResult {}

/// Ok when every number of `step`'s record is finite.
pub fn check_finite(step: &Step) -> Result<(), NonFiniteResult> {
    let mut finder = Finder::default();
    // The finder's serializer never fails; a failure would only mean nothing was found.
    let _ = step.record.serialize(&mut finder);
    match finder.found {
        Some((quantity, value)) => Err(NonFiniteResult {
            analysis: step.title.clone(),
            quantity,
            value,
        }),
        None => Ok(()),
    }
}

/// One step of a path into the record: a field or variant name, a map key, or an index.
enum Segment {
    Name(&'static str),
    Key(String),
    Index(usize),
}

/// A serializer that remembers the path of the first non-finite float. The path is kept as
/// segments and spelt out only when one is found: a record of millions of numbers is walked
/// without an allocation per number.
#[derive(Default)]
struct Finder {
    path: Vec<Segment>,
    index: Vec<usize>,
    found: Option<(String, f64)>,
}

impl Finder {
    fn float(&mut self, value: f64) {
        if !value.is_finite() && self.found.is_none() {
            let mut path = String::new();
            for segment in &self.path {
                match segment {
                    Segment::Index(i) => path.push_str(&format!("[{i}]")),
                    Segment::Name(name) => push_name(&mut path, name),
                    Segment::Key(key) => push_name(&mut path, key),
                }
            }
            self.found = Some((path, value));
        }
    }

    fn visit<T: ?Sized + Serialize>(&mut self, segment: Segment, value: &T) -> Result<(), Never> {
        self.path.push(segment);
        let result = value.serialize(&mut *self);
        self.path.pop();
        result
    }

    fn element<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), Never> {
        let i = self.index.last().copied().unwrap_or(0);
        if let Some(last) = self.index.last_mut() {
            *last += 1;
        }
        self.visit(Segment::Index(i), value)
    }

    fn open(&mut self) -> Result<&mut Finder, Never> {
        self.index.push(0);
        Ok(self)
    }

    fn close(&mut self) -> Result<(), Never> {
        self.index.pop();
        Ok(())
    }
}

/// Appends `.name` to `path` (without the dot at its start).
fn push_name(path: &mut String, name: &str) {
    if !path.is_empty() {
        path.push('.');
    }
    path.push_str(name);
}

/// The finder's error type; it is never produced by the finder itself.
#[derive(Debug)]
struct Never(String);

impl std::fmt::Display for Never {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Never {}

impl ser::Error for Never {
    fn custom<T: std::fmt::Display>(msg: T) -> Self {
        Never(msg.to_string())
    }
}

/// Methods that see no float: they succeed without looking further.
macro_rules! ignore {
    ($($method:ident($($ty:ty),*);)*) => {
        $(fn $method(self, $(_: $ty),*) -> Result<(), Never> { Ok(()) })*
    };
}

impl<'a> ser::Serializer for &'a mut Finder {
    type Ok = ();
    type Error = Never;
    type SerializeSeq = &'a mut Finder;
    type SerializeTuple = &'a mut Finder;
    type SerializeTupleStruct = &'a mut Finder;
    type SerializeTupleVariant = &'a mut Finder;
    type SerializeMap = &'a mut Finder;
    type SerializeStruct = &'a mut Finder;
    type SerializeStructVariant = &'a mut Finder;

    ignore! {
        serialize_bool(bool); serialize_i8(i8); serialize_i16(i16); serialize_i32(i32);
        serialize_i64(i64); serialize_u8(u8); serialize_u16(u16); serialize_u32(u32);
        serialize_u64(u64); serialize_char(char); serialize_str(&str); serialize_bytes(&[u8]);
        serialize_none(); serialize_unit(); serialize_unit_struct(&'static str);
        serialize_unit_variant(&'static str, u32, &'static str);
    }

    fn serialize_f32(self, v: f32) -> Result<(), Never> {
        self.float(f64::from(v));
        Ok(())
    }
    fn serialize_f64(self, v: f64) -> Result<(), Never> {
        self.float(v);
        Ok(())
    }
    fn serialize_some<T: ?Sized + Serialize>(self, value: &T) -> Result<(), Never> {
        value.serialize(self)
    }
    fn serialize_newtype_struct<T: ?Sized + Serialize>(self, _: &'static str, value: &T) -> Result<(), Never> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Never> {
        self.visit(Segment::Name(variant), value)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self, Never> {
        self.open()
    }
    fn serialize_tuple(self, _: usize) -> Result<Self, Never> {
        self.open()
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Self, Never> {
        self.open()
    }
    fn serialize_tuple_variant(self, _: &'static str, _: u32, _: &'static str, _: usize) -> Result<Self, Never> {
        self.open()
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self, Never> {
        self.open()
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self, Never> {
        self.open()
    }
    fn serialize_struct_variant(self, _: &'static str, _: u32, _: &'static str, _: usize) -> Result<Self, Never> {
        self.open()
    }
}

/// Implements the element-wise compound serializers by [`Finder::element`].
macro_rules! elements {
    ($($trait:ident::$method:ident;)*) => {$(
        impl ser::$trait for &mut Finder {
            type Ok = ();
            type Error = Never;
            fn $method<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), Never> {
                self.element(value)
            }
            fn end(self) -> Result<(), Never> {
                self.close()
            }
        }
    )*};
}

elements! {
    SerializeSeq::serialize_element;
    SerializeTuple::serialize_element;
    SerializeTupleStruct::serialize_field;
    SerializeTupleVariant::serialize_field;
}

/// Implements the keyed compound serializers: the path grows by the field's name.
macro_rules! fields {
    ($($trait:ident;)*) => {$(
        impl ser::$trait for &mut Finder {
            type Ok = ();
            type Error = Never;
            fn serialize_field<T: ?Sized + Serialize>(&mut self, key: &'static str, value: &T) -> Result<(), Never> {
                self.visit(Segment::Name(key), value)
            }
            fn end(self) -> Result<(), Never> {
                self.close()
            }
        }
    )*};
}

fields! {
    SerializeStruct;
    SerializeStructVariant;
}

impl ser::SerializeMap for &mut Finder {
    type Ok = ();
    type Error = Never;
    fn serialize_key<T: ?Sized + Serialize>(&mut self, key: &T) -> Result<(), Never> {
        let name = serde_json::to_string(key).unwrap_or_default();
        self.path.push(Segment::Key(name.trim_matches('"').to_string()));
        Ok(())
    }
    fn serialize_value<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), Never> {
        let result = value.serialize(&mut **self);
        self.path.pop();
        result
    }
    fn end(self) -> Result<(), Never> {
        self.close()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::{LibraryRecord, Step};

    #[derive(Serialize)]
    struct Inner {
        values: Vec<f64>,
        omega_sq: Option<f64>,
    }

    fn path_of(value: &impl Serialize) -> Option<(String, f64)> {
        let mut finder = Finder::default();
        let _ = value.serialize(&mut finder);
        finder.found
    }

    #[test]
    fn the_first_non_finite_number_is_found_with_its_path() {
        let inner = |values: Vec<f64>| Inner { values, omega_sq: None };
        let records = vec![inner(vec![1.0, 2.0]), inner(vec![3.0, f64::INFINITY, f64::NAN])];
        let (path, value) = path_of(&records).expect("found");
        assert_eq!((path.as_str(), value), ("[1].values[1]", f64::INFINITY));
        assert_eq!(path_of(&vec![inner(vec![0.0; 3])]), None);
        let mut map = std::collections::BTreeMap::new();
        map.insert(
            "modes",
            vec![Inner {
                values: vec![],
                omega_sq: Some(f64::NAN),
            }],
        );
        let (path, value) = path_of(&map).expect("found");
        assert!(path == "modes[0].omega_sq" && value.is_nan(), "{path}");
    }

    #[test]
    fn a_finite_step_passes() {
        let step = Step::new(
            "library",
            0.0,
            LibraryRecord {
                abi_version: 1,
                feature_bits: 3,
                features: vec!["kinematics".into(), "mass".into()],
            },
        );
        assert_eq!(check_finite(&step), Ok(()));
    }
}
