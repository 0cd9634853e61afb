//! One linear pass over a URDF text before it is parsed: elements nested deeper than
//! [`MAX_NESTING`] are refused (the XML parsers underneath recurse once per level, so a deep
//! hostile file would overflow the stack), and `<texture>` elements without a `filename`
//! attribute are dropped (some exporters write `<texture/>` in materials, which the parser
//! refuses; materials only concern rendering).
//!
//! The scan knows XML's lexical structure: comments, CDATA sections, processing instructions
//! and declarations are skipped whole, and a tag ends at the first `>` outside quotes (`>` is
//! legal inside attribute values). A text it cannot follow is passed on unchanged, for the
//! parser to reject with its own message.

use crate::UrdfError;
use std::borrow::Cow;

/// The deepest element nesting accepted; URDF needs six levels (robot, link, visual,
/// geometry, mesh) and simulator extensions a few more.
pub const MAX_NESTING: usize = 64;

/// `text` without its bare `<texture>` elements, or an error when elements nest deeper than
/// [`MAX_NESTING`].
pub(crate) fn prepared(text: &str) -> Result<Cow<'_, str>, UrdfError> {
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
    if scan.removed.is_empty() {
        return Ok(Cow::Borrowed(text));
    }
    let mut kept = String::with_capacity(text.len());
    let mut from = 0;
    for &(start, end) in &scan.removed {
        kept.push_str(&text[from..start]);
        from = end;
    }
    kept.push_str(&text[from..]);
    Ok(Cow::Owned(kept))
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

/// The state of the scan: the current depth, the open bare texture (its start and depth) and
/// the spans to remove.
#[derive(Default)]
struct Scan {
    depth: usize,
    open_texture: Option<(usize, usize)>,
    removed: Vec<(usize, usize)>,
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
        let bare_texture = self.open_texture.is_none() && is_bare_texture(inner.trim_end_matches('/'));
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

/// Whether the tag body `inner` (name and attributes) is a `texture` without a `filename`
/// attribute; an attribute list it cannot read counts as having one (the tag is kept).
fn is_bare_texture(inner: &str) -> bool {
    let name_end = inner.find(|c: char| c.is_whitespace()).unwrap_or(inner.len());
    if &inner[..name_end] != "texture" {
        return false;
    }
    let mut rest = inner[name_end..].trim_start();
    while !rest.is_empty() {
        let Some((name, after)) = rest.split_once('=') else {
            return false;
        };
        if name.trim() == "filename" {
            return false;
        }
        let after = after.trim_start();
        let Some(quote) = after.chars().next().filter(|c| *c == '"' || *c == '\'') else {
            return false;
        };
        let Some(close) = after[1..].find(quote) else {
            return false;
        };
        rest = after[1 + close + 1..].trim_start();
    }
    true
}
