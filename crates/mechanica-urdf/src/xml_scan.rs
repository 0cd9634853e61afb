//! One linear pass over a URDF text before it is parsed: elements nested deeper than
//! [`MAX_NESTING`] are refused (the XML parsers underneath recurse once per level, so a deep
//! hostile file would overflow the stack), and `<texture>` elements without a `filename`
//! attribute are dropped (some exporters write `<texture/>` in materials, which the parser
//! refuses; materials only concern rendering). The same pass notes which links declare an
//! `<inertial>` element, which the parsed robot does not tell apart from a zero one.
//!
//! The scan knows XML's lexical structure: comments, CDATA sections, processing instructions
//! and declarations are skipped whole, and a tag ends at the first `>` outside quotes (`>` is
//! legal inside attribute values). A text it cannot follow is passed on unchanged, for the
//! parser to reject with its own message.

use crate::UrdfError;
use std::borrow::Cow;
use std::collections::HashSet;

/// The deepest element nesting accepted; URDF needs six levels (robot, link, visual,
/// geometry, mesh) and simulator extensions a few more.
pub const MAX_NESTING: usize = 64;

/// A URDF text ready for the parser, and what the scan learnt on the way.
pub(crate) struct Prepared<'a> {
    /// The text without its bare `<texture>` elements.
    pub text: Cow<'a, str>,
    /// The names of the links (children of the root element) with an `<inertial>` child.
    pub links_with_inertial: HashSet<String>,
}

/// `text` prepared for the parser, or an error when elements nest deeper than [`MAX_NESTING`].
pub(crate) fn prepared(text: &str) -> Result<Prepared<'_>, UrdfError> {
    let mut scan = Scan::default();
    let mut at = 0;
    while let Some(offset) = text[at..].find('<') {
        let start = at + offset;
        let Some(end) = markup_end(text, start) else {
            break;
        };
        scan.tag(&text[start..end], start, end)?;
        at = end;
    }
    let text = if scan.removed.is_empty() {
        Cow::Borrowed(text)
    } else {
        let mut kept = String::with_capacity(text.len());
        let mut from = 0;
        for &(start, end) in &scan.removed {
            kept.push_str(&text[from..start]);
            from = end;
        }
        kept.push_str(&text[from..]);
        Cow::Owned(kept)
    };
    Ok(Prepared {
        text,
        links_with_inertial: scan.links_with_inertial,
    })
}

/// The end (one past the last byte) of the markup that starts with `<` at `start`: a comment,
/// CDATA section, processing instruction, declaration or tag; None when it does not end.
fn markup_end(text: &str, start: usize) -> Option<usize> {
    let rest = &text[start..];
    let closing = |opening: &str, closing: &str| {
        rest[opening.len()..]
            .find(closing)
            .map(|i| start + opening.len() + i + closing.len())
    };
    if rest.starts_with("<!--") {
        closing("<!--", "-->")
    } else if rest.starts_with("<![CDATA[") {
        closing("<![CDATA[", "]]>")
    } else if rest.starts_with("<?") {
        closing("<?", "?>")
    } else {
        // A tag or a declaration: the first '>' outside quotes and (for a declaration's
        // internal subset) outside brackets.
        let (mut quote, mut brackets) = (None, 0usize);
        for (i, c) in rest.char_indices().skip(1) {
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, '"' | '\'') => quote = Some(c),
                (None, '[') => brackets += 1,
                (None, ']') => brackets = brackets.saturating_sub(1),
                (None, '>') if brackets == 0 => return Some(start + i + 1),
                _ => {}
            }
        }
        None
    }
}

/// The state of the scan: the current depth, the open bare texture (its start and depth), the
/// spans to remove, the name of the open link and the links seen with an `<inertial>`.
#[derive(Default)]
struct Scan {
    depth: usize,
    open_texture: Option<(usize, usize)>,
    removed: Vec<(usize, usize)>,
    open_link: Option<String>,
    links_with_inertial: HashSet<String>,
}

impl Scan {
    /// Takes the markup `markup` spanning `start..end`.
    fn tag(&mut self, markup: &str, start: usize, end: usize) -> Result<(), UrdfError> {
        if markup.starts_with("<!") || markup.starts_with("<?") {
            return Ok(());
        }
        if markup.starts_with("</") {
            self.depth = self.depth.saturating_sub(1);
            if let Some((texture_start, depth)) = self.open_texture
                && depth == self.depth
            {
                self.removed.push((texture_start, end));
                self.open_texture = None;
            }
            return Ok(());
        }
        let inner = markup.trim_start_matches('<').trim_end_matches('>');
        let self_closing = inner.ends_with('/');
        let (name, attributes) = split_tag(inner.trim_end_matches('/'));
        self.note_inertial(name, attributes, self_closing);
        let bare_texture =
            self.open_texture.is_none() && name == "texture" && attribute(attributes, "filename").is_none();
        if self_closing {
            if bare_texture {
                self.removed.push((start, end));
            }
            return Ok(());
        }
        if bare_texture {
            self.open_texture = Some((start, self.depth));
        }
        self.depth += 1;
        if self.depth > MAX_NESTING {
            return Err(UrdfError::Parse {
                message: format!("elements nested deeper than {MAX_NESTING} levels (at byte {start})"),
            });
        }
        Ok(())
    }
}

impl Scan {
    /// Follows the opening tag `name` at the current depth: a link (a child of the root
    /// element) opens, or an `<inertial>` inside the open link marks it.
    fn note_inertial(&mut self, name: &str, attributes: &str, self_closing: bool) {
        match (self.depth, name) {
            (1, "link") => self.open_link = (!self_closing).then(|| attribute(attributes, "name")).flatten(),
            (1, _) => self.open_link = None,
            (2, "inertial") => {
                if let Some(link) = &self.open_link {
                    self.links_with_inertial.insert(link.clone());
                }
            }
            _ => {}
        }
    }
}

/// The tag body `inner` split into its name and its attribute list.
fn split_tag(inner: &str) -> (&str, &str) {
    let name_end = inner.find(|c: char| c.is_whitespace()).unwrap_or(inner.len());
    (&inner[..name_end], &inner[name_end..])
}

/// The value of the attribute `wanted` in the attribute list `attributes` (as written, entities
/// not expanded); an attribute list it cannot read counts as having the attribute with an empty
/// value (so that a bare texture it cannot read is kept).
fn attribute(attributes: &str, wanted: &str) -> Option<String> {
    let mut rest = attributes.trim_start();
    while !rest.is_empty() {
        let Some((name, after)) = rest.split_once('=') else {
            return Some(String::new());
        };
        let after = after.trim_start();
        let Some(quote) = after.chars().next().filter(|c| *c == '"' || *c == '\'') else {
            return Some(String::new());
        };
        let Some(close) = after[1..].find(quote) else {
            return Some(String::new());
        };
        if name.trim() == wanted {
            return Some(unescaped(&after[1..1 + close]));
        }
        rest = after[1 + close + 1..].trim_start();
    }
    None
}

/// `value` with XML's predefined entities and character references (`&#38;`, `&#x26;`)
/// replaced; any other `&…;` is left as written.
fn unescaped(value: &str) -> String {
    let mut text = String::with_capacity(value.len());
    let mut rest = value;
    while let Some(at) = rest.find('&') {
        text.push_str(&rest[..at]);
        let reference = &rest[at + 1..];
        let decoded = reference.find(';').and_then(|end| {
            let name = &reference[..end];
            let character = match name {
                "lt" => Some('<'),
                "gt" => Some('>'),
                "quot" => Some('"'),
                "apos" => Some('\''),
                "amp" => Some('&'),
                _ => name
                    .strip_prefix("#x")
                    .map(|hex| u32::from_str_radix(hex, 16))
                    .or_else(|| name.strip_prefix('#').map(str::parse))
                    .and_then(Result::ok)
                    .and_then(char::from_u32),
            };
            character.map(|c| (c, end))
        });
        match decoded {
            Some((c, end)) => {
                text.push(c);
                rest = &reference[end + 1..];
            }
            None => {
                text.push('&');
                rest = reference;
            }
        }
    }
    text.push_str(rest);
    text
}
