//! OGC well-known text (WKT) of a coordinate reference system, read as a tree: `KEYWORD[arg, …]`,
//! each argument a quoted text, a number, a bare word (WKT2's enumerations: `Cartesian`,
//! `north`) or a nested node. WKT1 (OGC 01-009), ESRI's variant of it and WKT2 (ISO 19162) share
//! this grammar; `(`…`)` delimit as `[`…`]` do, and WKT2's doubled quote (`""`) stands for one
//! quote inside a text. What the nodes mean is the caller's (`las_crs`).
//!
//! **Hostile input** (a file's record): nesting deeper than [`MAX_DEPTH`] is refused rather than
//! recursed into, so the stack is bounded; the work is linear in the text's length.
//! **Panics**: none.

/// The deepest nesting read. Real coordinate systems nest about eight deep (a compound system's
/// projected part's base system's datum's ellipsoid's identifier).
pub const MAX_DEPTH: usize = 32;

/// One `KEYWORD[…]` (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    pub keyword: String,
    pub args: Vec<Arg>,
}

/// An argument of a [`Node`].
#[derive(Debug, Clone, PartialEq)]
pub enum Arg {
    Text(String),
    Number(f64),
    Word(String),
    Node(Node),
}

impl Node {
    /// Whether this node's keyword is one of `keywords` (WKT keywords are case-insensitive).
    pub fn is(&self, keywords: &[&str]) -> bool {
        keywords.iter().any(|k| self.keyword.eq_ignore_ascii_case(k))
    }

    /// The nodes among this node's arguments, in order.
    pub fn children(&self) -> impl Iterator<Item = &Node> {
        self.args.iter().filter_map(|a| match a {
            Arg::Node(n) => Some(n),
            _ => None,
        })
    }

    /// The first child node whose keyword is one of `keywords`.
    pub fn child(&self, keywords: &[&str]) -> Option<&Node> {
        self.children().find(|n| n.is(keywords))
    }

    /// The first argument that is a number.
    pub fn first_number(&self) -> Option<f64> {
        self.args.iter().find_map(|a| match a {
            Arg::Number(x) => Some(*x),
            _ => None,
        })
    }

    /// The first argument that is a bare word.
    pub fn first_word(&self) -> Option<&str> {
        self.args.iter().find_map(|a| match a {
            Arg::Word(w) => Some(w.as_str()),
            _ => None,
        })
    }
}

/// The node `text` holds (whitespace and NULs around it allowed, as records pad their text);
/// `None` where it is not well-formed WKT or nests deeper than [`MAX_DEPTH`].
pub fn parse(text: &str) -> Option<Node> {
    let mut reader = Reader {
        text: text.as_bytes(),
        at: 0,
    };
    let keyword = reader.word()?;
    let node = reader.node(keyword, 0)?;
    reader.skip_space();
    (reader.at == reader.text.len()).then_some(node)
}

struct Reader<'t> {
    text: &'t [u8],
    at: usize,
}

impl Reader<'_> {
    fn peek(&self) -> Option<u8> {
        self.text.get(self.at).copied()
    }

    fn skip_space(&mut self) {
        while self.peek().is_some_and(|c| c.is_ascii_whitespace() || c == 0) {
            self.at += 1;
        }
    }

    /// A keyword or bare word: a letter, then letters, digits and underscores.
    fn word(&mut self) -> Option<String> {
        self.skip_space();
        let start = self.at;
        if !self.peek()?.is_ascii_alphabetic() {
            return None;
        }
        while self.peek().is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_') {
            self.at += 1;
        }
        // Only ASCII was taken, so the slice is text.
        std::str::from_utf8(&self.text[start..self.at]).ok().map(str::to_owned)
    }

    /// The rest of a node whose keyword was read: `[arg, …]` (or `(…)`); a keyword without
    /// brackets is a bare word, which the caller decides.
    fn node(&mut self, keyword: String, depth: usize) -> Option<Node> {
        if depth >= MAX_DEPTH {
            return None;
        }
        self.skip_space();
        let close = match self.peek()? {
            b'[' => b']',
            b'(' => b')',
            _ => return None,
        };
        self.at += 1;
        let mut args = Vec::new();
        self.skip_space();
        if self.peek() == Some(close) {
            self.at += 1;
            return Some(Node { keyword, args });
        }
        loop {
            args.push(self.arg(depth)?);
            self.skip_space();
            match self.peek()? {
                b',' => self.at += 1,
                c if c == close => {
                    self.at += 1;
                    return Some(Node { keyword, args });
                }
                _ => return None,
            }
        }
    }

    fn arg(&mut self, depth: usize) -> Option<Arg> {
        self.skip_space();
        match self.peek()? {
            b'"' => self.quoted().map(Arg::Text),
            c if c.is_ascii_digit() || matches!(c, b'+' | b'-' | b'.') => self.number().map(Arg::Number),
            _ => {
                let word = self.word()?;
                self.skip_space();
                if matches!(self.peek(), Some(b'[' | b'(')) {
                    self.node(word, depth + 1).map(Arg::Node)
                } else {
                    Some(Arg::Word(word))
                }
            }
        }
    }

    /// A text between quotes, a doubled quote standing for one.
    fn quoted(&mut self) -> Option<String> {
        self.at += 1;
        let mut bytes = Vec::new();
        loop {
            let c = self.peek()?;
            self.at += 1;
            if c == b'"' {
                if self.peek() == Some(b'"') {
                    self.at += 1;
                } else {
                    return Some(String::from_utf8_lossy(&bytes).into_owned());
                }
            }
            bytes.push(c);
        }
    }

    fn number(&mut self) -> Option<f64> {
        let start = self.at;
        while self
            .peek()
            .is_some_and(|c| c.is_ascii_digit() || matches!(c, b'+' | b'-' | b'.' | b'e' | b'E'))
        {
            self.at += 1;
        }
        std::str::from_utf8(&self.text[start..self.at]).ok()?.parse().ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_texts_numbers_and_words() {
        let node = parse(
            "PROJCRS[\"a \"\"quoted\"\" name\",CS[Cartesian,2],\n AXIS[\"easting\",east, ORDER[1]],\
             LENGTHUNIT(\"metre\",1.0E0)]\0\0",
        )
        .expect("parsed");
        assert!(node.is(&["projcrs"]));
        assert_eq!(node.args[0], Arg::Text("a \"quoted\" name".to_owned()));
        assert_eq!(node.child(&["CS"]).and_then(Node::first_word), Some("Cartesian"));
        assert_eq!(node.child(&["CS"]).and_then(Node::first_number), Some(2.0));
        let axis = node.child(&["AXIS"]).expect("axis");
        assert_eq!(axis.first_word(), Some("east"));
        assert_eq!(axis.child(&["ORDER"]).and_then(Node::first_number), Some(1.0));
        assert_eq!(node.child(&["LENGTHUNIT"]).and_then(Node::first_number), Some(1.0));
        assert_eq!(node.children().count(), 3);
    }

    #[test]
    fn malformed_text_is_none() {
        for text in [
            "",
            "PROJCS",
            "PROJCS[\"unterminated",
            "PROJCS[\"a\"",
            "PROJCS[\"a\"]]",
            "PROJCS[\"a\" \"b\"]",
            "PROJCS[\"a\",UNIT[\"foot\",0.3.0]]",
            "PROJCS[\"a\",]",
            "PROJCS[\"a\")",
            "[\"a\"]",
            "PROJCS[\"a\"] trailing",
        ] {
            assert_eq!(parse(text), None, "{text:?}");
        }
        assert!(parse("UNIT[]").is_some_and(|n| n.args.is_empty()));
    }

    #[test]
    fn deep_nesting_is_refused_without_recursing_into_it() {
        let deep = |n: usize| format!("{}{}", "A[".repeat(n), "]".repeat(n));
        assert!(parse(&deep(MAX_DEPTH)).is_some());
        assert_eq!(parse(&deep(MAX_DEPTH + 1)), None);
        // Far deeper than a stack would hold, were it recursed into.
        assert_eq!(parse(&deep(1_000_000)), None);
    }
}
