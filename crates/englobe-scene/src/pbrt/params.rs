//! Parameter lists, the `"type name" value` pairs after a directive (pbrt-v4's file format,
//! "Parameter lists"): `"float fov" [ 45 ]`, `"rgb L" [ 17 12 4 ]`, `"string filename" "a.ply"`,
//! `"bool twosided" true`. A value is one token or a bracketed list. The types are pbrt-v4's
//! (`integer float point2 vector2 point3 vector3 normal3 normal rgb spectrum blackbody string bool
//! texture`) and pbrt-v3's synonyms (`point vector color`); numbers are finite and fit a 32-bit
//! float, integers fit 32 bits.
//!
//! Every parameter remembers whether the scene builder read it, so that those it did not are
//! reported by name and place.

use std::cell::Cell;

use super::lexer::{Kind, Lexer};
use super::source::{Place, Res, fail};

/// A parameter's declared type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Type {
    Integer,
    Float,
    Point2,
    Vector2,
    Point3,
    Vector3,
    Normal,
    Rgb,
    Spectrum,
    Blackbody,
    String,
    Bool,
    Texture,
}

impl Type {
    fn parse(word: &str) -> Option<Type> {
        Some(match word {
            "integer" => Type::Integer,
            "float" => Type::Float,
            "point2" => Type::Point2,
            "vector2" => Type::Vector2,
            "point3" | "point" => Type::Point3,
            "vector3" | "vector" => Type::Vector3,
            "normal3" | "normal" => Type::Normal,
            "rgb" | "color" => Type::Rgb,
            "spectrum" => Type::Spectrum,
            "blackbody" => Type::Blackbody,
            "string" => Type::String,
            "bool" => Type::Bool,
            "texture" => Type::Texture,
            _ => return None,
        })
    }

    /// The pbrt-v4 name.
    pub fn name(self) -> &'static str {
        match self {
            Type::Integer => "integer",
            Type::Float => "float",
            Type::Point2 => "point2",
            Type::Vector2 => "vector2",
            Type::Point3 => "point3",
            Type::Vector3 => "vector3",
            Type::Normal => "normal",
            Type::Rgb => "rgb",
            Type::Spectrum => "spectrum",
            Type::Blackbody => "blackbody",
            Type::String => "string",
            Type::Bool => "bool",
            Type::Texture => "texture",
        }
    }

    /// How many numbers make one value (0 for strings and booleans).
    fn arity(self) -> usize {
        match self {
            Type::Integer | Type::Float | Type::Blackbody => 1,
            Type::Point2 | Type::Vector2 => 2,
            Type::Point3 | Type::Vector3 | Type::Normal | Type::Rgb => 3,
            Type::Spectrum => 2,
            Type::String | Type::Bool | Type::Texture => 0,
        }
    }
}

/// A parameter's values.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Values {
    Numbers(Vec<f64>),
    Strings(Vec<String>),
    Bools(Vec<bool>),
}

/// One parameter.
#[derive(Clone, Debug)]
pub(super) struct Param {
    pub ty: Type,
    pub name: String,
    pub values: Values,
    /// The declaration (`"float fov"`).
    pub at: Place,
    used: Cell<bool>,
}

impl Param {
    /// `"type name"` as a message shows it.
    pub fn shown(&self) -> String {
        format!("\"{} {}\"", self.ty.name(), self.name)
    }

    fn numbers(&self) -> &[f64] {
        match &self.values {
            Values::Numbers(v) => v,
            _ => &[],
        }
    }
}

/// The parameters of one directive.
#[derive(Clone, Debug, Default)]
pub(super) struct Params {
    list: Vec<Param>,
}

/// Most parameters one directive may carry.
const MAX_PARAMS: usize = 4096;

/// Reads the parameter list that follows a directive's own arguments: pairs of a declaration
/// string and a value, up to the next token that is not a string.
pub(super) fn parse_params(lex: &mut Lexer) -> Res<Params> {
    let mut list: Vec<Param> = Vec::new();
    while let Some(t) = lex.peek()? {
        if !matches!(t.kind, Kind::Str { .. }) {
            break;
        }
        lex.next()?;
        let at = lex.place(t.start);
        let decl = lex.string(&t).into_owned();
        let mut words = decl.split_ascii_whitespace();
        let (Some(ty_word), Some(name), None) = (words.next(), words.next(), words.next()) else {
            return fail(
                at,
                format!("expected a parameter declaration \"type name\", such as \"float fov\", found \"{decl}\""),
            );
        };
        let Some(ty) = Type::parse(ty_word) else {
            return fail(
                at,
                format!(
                    "unknown parameter type `{ty_word}` in \"{decl}\": expected integer, float, point2, vector2, \
                     point3, vector3, normal, rgb, spectrum, blackbody, string, bool or texture"
                ),
            );
        };
        if list.iter().any(|p| p.name == name) {
            return fail(at, format!("parameter `{name}` is given twice"));
        }
        if list.len() >= MAX_PARAMS {
            return fail(at, format!("more than {MAX_PARAMS} parameters in one directive"));
        }
        let values = parse_values(lex, ty, &decl, at)?;
        list.push(Param { ty, name: name.to_owned(), values, at, used: Cell::new(false) });
    }
    Ok(Params { list })
}

/// A parameter's value: one token, or a bracketed list of tokens.
fn parse_values(lex: &mut Lexer, ty: Type, decl: &str, at: Place) -> Res<Values> {
    let Some(first) = lex.next()? else {
        return fail(lex.end_place(), format!("the file ends before the value of \"{decl}\""));
    };
    let bracketed = first.kind == Kind::Open;
    let mut numbers = Vec::new();
    let mut strings = Vec::new();
    let mut bools = Vec::new();
    let mut token = if bracketed { lex.next()? } else { Some(first) };
    loop {
        let Some(t) = token else {
            return fail(lex.place(first.start), format!("the `[` of \"{decl}\" is never closed"));
        };
        if bracketed && t.kind == Kind::Close {
            break;
        }
        let here = lex.place(t.start);
        match (ty, t.kind) {
            (Type::String | Type::Texture, Kind::Str { .. }) => strings.push(lex.string(&t).into_owned()),
            (Type::Spectrum, Kind::Str { .. }) => strings.push(lex.string(&t).into_owned()),
            (Type::Bool, Kind::Str { .. } | Kind::Word) => match &*lex.string(&t) {
                "true" => bools.push(true),
                "false" => bools.push(false),
                other => return fail(here, format!("\"{decl}\": expected true or false, found `{other}`")),
            },
            (Type::String | Type::Texture, _) => {
                return fail(here, format!("\"{decl}\": expected a quoted string, found `{}`", lex.slice(&t)));
            }
            (_, Kind::Word) => numbers.push(number(lex.slice(&t), ty, decl, here)?),
            (_, _) => return fail(here, format!("\"{decl}\": expected a number, found `{}`", lex.slice(&t))),
        }
        if !bracketed {
            break;
        }
        token = lex.next()?;
    }
    let values = match ty {
        Type::String | Type::Texture => Values::Strings(strings),
        Type::Bool => Values::Bools(bools),
        Type::Spectrum if !strings.is_empty() => {
            if !numbers.is_empty() || strings.len() != 1 {
                return fail(at, format!("\"{decl}\": expected pairs of numbers or one spectrum name"));
            }
            Values::Strings(strings)
        }
        _ => Values::Numbers(numbers),
    };
    let count = match &values {
        Values::Numbers(v) => v.len(),
        Values::Strings(v) => v.len(),
        Values::Bools(v) => v.len(),
    };
    if count == 0 {
        return fail(at, format!("\"{decl}\" has no value"));
    }
    if let Values::Numbers(v) = &values
        && v.len() % ty.arity() != 0
    {
        let what = match ty {
            Type::Spectrum => "pairs of a wavelength and a value".to_owned(),
            _ => format!("a multiple of {} numbers", ty.arity()),
        };
        return fail(at, format!("\"{decl}\" has {} numbers: expected {what}", v.len()));
    }
    Ok(values)
}

/// A number token: finite, within `f32`'s range, and whole for integers.
fn number(word: &str, ty: Type, decl: &str, at: Place) -> Res<f64> {
    let v: f64 = match word.parse() {
        Ok(v) => v,
        Err(_) => return fail(at, format!("\"{decl}\": expected a number, found `{word}`")),
    };
    if !v.is_finite() || v.abs() > f32::MAX as f64 {
        return fail(at, format!("\"{decl}\": {word} is not a finite number that fits a 32-bit float"));
    }
    if ty == Type::Integer && (v.fract() != 0.0 || word.contains(['.', 'e', 'E']) || v.abs() > i32::MAX as f64) {
        return fail(at, format!("\"{decl}\": expected a whole number that fits 32 bits, found `{word}`"));
    }
    Ok(v)
}

impl Params {
    /// An empty list, for defaults.
    pub fn none() -> Self {
        Params::default()
    }

    /// The parameter called `name`, if its type is one of `types` (marked as read); a parameter of
    /// that name and another type is an error.
    pub fn get(&self, name: &str, types: &[Type]) -> Res<Option<&Param>> {
        let Some(p) = self.list.iter().find(|p| p.name == name) else { return Ok(None) };
        if !types.contains(&p.ty) {
            let expected: Vec<String> = types.iter().map(|t| format!("\"{} {name}\"", t.name())).collect();
            return fail(
                p.at,
                format!("parameter {} has the wrong type: expected {}", p.shown(), expected.join(" or ")),
            );
        }
        p.used.set(true);
        Ok(Some(p))
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The place of parameter `name`'s declaration, or `or` if it is absent.
    pub fn at_or(&self, name: &str, or: Place) -> Place {
        self.list.iter().find(|p| p.name == name).map_or(or, |p| p.at)
    }

    /// True if a parameter called `name` is present (whatever its type); does not mark it read.
    pub fn has(&self, name: &str) -> bool {
        self.list.iter().any(|p| p.name == name)
    }

    /// Marks `name` as read without reading it (parameters that are reported by other means).
    pub fn touch(&self, name: &str) -> Option<&Param> {
        let p = self.list.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// The numbers of parameter `name` of type `ty`.
    pub fn numbers(&self, name: &str, types: &[Type]) -> Res<Option<(&[f64], Place)>> {
        Ok(self.get(name, types)?.map(|p| (p.numbers(), p.at)))
    }

    /// The one number of `name` (a float; an integer where `Type::Integer` is asked).
    pub fn one(&self, name: &str, ty: Type) -> Res<Option<f64>> {
        let Some(p) = self.get(name, &[ty])? else { return Ok(None) };
        match p.numbers() {
            [v] => Ok(Some(*v)),
            v => fail(p.at, format!("parameter {} takes one value, found {}", p.shown(), v.len())),
        }
    }

    pub fn float(&self, name: &str) -> Res<Option<f64>> {
        self.one(name, Type::Float)
    }

    pub fn integer(&self, name: &str) -> Res<Option<i64>> {
        Ok(self.one(name, Type::Integer)?.map(|v| v as i64))
    }

    /// The one string of `name`.
    pub fn string(&self, name: &str) -> Res<Option<(&str, Place)>> {
        let Some(p) = self.get(name, &[Type::String])? else { return Ok(None) };
        match &p.values {
            Values::Strings(v) if v.len() == 1 => Ok(Some((&v[0], p.at))),
            _ => fail(p.at, format!("parameter {} takes one string", p.shown())),
        }
    }

    pub fn bool(&self, name: &str) -> Res<Option<bool>> {
        let Some(p) = self.get(name, &[Type::Bool])? else { return Ok(None) };
        match &p.values {
            Values::Bools(v) if v.len() == 1 => Ok(Some(v[0])),
            _ => fail(p.at, format!("parameter {} takes one value", p.shown())),
        }
    }

    /// The parameters nobody read, in file order.
    pub fn unused(&self) -> impl Iterator<Item = &Param> {
        self.list.iter().filter(|p| !p.used.get())
    }
}

#[cfg(test)]
mod tests {
    use super::super::source::Fail;
    use super::*;

    fn params(text: &str) -> Res<Params> {
        let mut lex = Lexer::new(std::sync::Arc::new(text.to_owned()), 0);
        parse_params(&mut lex)
    }

    fn message(r: Res<Params>) -> String {
        match r {
            Err(Fail::At(_, m)) => m,
            other => panic!("expected an error, got {other:?}"),
        }
    }

    #[test]
    fn values_of_every_kind() {
        let p = params(
            "\"float fov\" [ 45 ] \"integer indices\" [0 1 2] \"string filename\" \"a.ply\" \"bool twosided\" true \
             \"point P\" [0 0 0 1 0 0] \"spectrum eta\" \"metal-Cu-eta\" \"blackbody L\" 6500 Shape",
        )
        .unwrap();
        assert_eq!(p.float("fov").unwrap(), Some(45.0));
        assert_eq!(p.numbers("indices", &[Type::Integer]).unwrap().unwrap().0, &[0.0, 1.0, 2.0]);
        assert_eq!(p.string("filename").unwrap().unwrap().0, "a.ply");
        assert_eq!(p.bool("twosided").unwrap(), Some(true));
        assert_eq!(p.numbers("P", &[Type::Point3]).unwrap().unwrap().0.len(), 6);
        assert!(matches!(p.get("eta", &[Type::Spectrum]).unwrap().unwrap().values, Values::Strings(_)));
        assert_eq!(p.unused().count(), 1, "the blackbody was not read");
        assert!(message(Ok(p.clone()).and_then(|p| p.float("filename").map(|_| p))).contains("wrong type"));
    }

    #[test]
    fn malformed_lists_are_refused() {
        assert!(message(params("\"float\" [1]")).contains("\"type name\""));
        assert!(message(params("\"real fov\" [1]")).contains("unknown parameter type `real`"));
        assert!(message(params("\"float fov\" [1")).contains("never closed"));
        assert!(message(params("\"integer n\" [1.5]")).contains("whole number"));
        assert!(message(params("\"float x\" [nan]")).contains("finite"));
        assert!(message(params("\"float x\" [1e39]")).contains("finite"));
        assert!(message(params("\"point3 P\" [1 2]")).contains("multiple of 3"));
        assert!(message(params("\"float a\" 1 \"float a\" 2")).contains("twice"));
        assert!(message(params("\"float a\" []")).contains("no value"));
        assert!(message(params("\"float a\" \"x\"")).contains("expected a number"));
        assert!(message(params("\"string a\" [ 1 ]")).contains("quoted string"));
        assert!(message(params("\"bool a\" maybe")).contains("true or false"));
        assert!(message(params("\"float a\"")).contains("ends before"));
    }
}
