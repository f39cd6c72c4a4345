//! A minimal XML element tree, enough to write renderer scene files with correct nesting and
//! escaping.

use std::fmt::{self, Write};

/// One XML element with attributes and child elements (no text content).
#[derive(Clone, Debug)]
pub(crate) struct Element {
    tag: &'static str,
    attributes: Vec<(&'static str, String)>,
    children: Vec<Element>,
}

impl Element {
    /// An element `<tag/>`.
    pub(crate) fn new(tag: &'static str) -> Element {
        Element {
            tag,
            attributes: Vec::new(),
            children: Vec::new(),
        }
    }

    /// Adds the attribute `name="value"`.
    pub(crate) fn attr(mut self, name: &'static str, value: impl fmt::Display) -> Element {
        self.attributes.push((name, value.to_string()));
        self
    }

    /// Adds a child element.
    pub(crate) fn child(mut self, child: Element) -> Element {
        self.children.push(child);
        self
    }

    /// Adds several child elements.
    pub(crate) fn children(mut self, children: impl IntoIterator<Item = Element>) -> Element {
        self.children.extend(children);
        self
    }

    /// The element as an XML document, with declaration and four-space indentation.
    pub(crate) fn to_document(&self) -> String {
        let mut text = String::from("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n");
        self.write(&mut text, 0)
            .expect("writing to a String cannot fail");
        text
    }

    fn write(&self, out: &mut String, depth: usize) -> fmt::Result {
        let indent = "    ".repeat(depth);
        write!(out, "{indent}<{}", self.tag)?;
        for (name, value) in &self.attributes {
            write!(out, " {name}=\"{}\"", escape(value))?;
        }
        if self.children.is_empty() {
            return writeln!(out, "/>");
        }
        writeln!(out, ">")?;
        for child in &self.children {
            child.write(out, depth + 1)?;
        }
        writeln!(out, "{indent}</{}>", self.tag)
    }
}

/// `value` with the five XML special characters replaced by entities.
fn escape(value: &str) -> String {
    value
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nests_indents_and_escapes() {
        let document = Element::new("scene")
            .attr("version", "3.0.0")
            .child(Element::new("string").attr("value", "a<b & \"c\""))
            .to_document();
        let expected = "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<scene version=\"3.0.0\">\n    \
                        <string value=\"a&lt;b &amp; &quot;c&quot;\"/>\n</scene>\n";
        assert_eq!(document, expected);
    }
}
