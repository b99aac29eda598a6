//! A sandboxed maths-expression language for curves written by a language model.
//!
//! An LLM describes a walking path as two formulas `x(t)` and `z(t)`. Its output is data, never
//! code: this module parses a formula into a flat postfix program that can do nothing but
//! arithmetic on one variable, with hard limits on its size, so hostile or broken text can at
//! worst produce an error.
//!
//! Written by hand because the expression crates evaluate richer languages (variables,
//! assignments, user functions, unbounded recursion) whose cost cannot be bounded per call;
//! here every limit (source length, tokens, nesting, stack depth, operations) is ours.
//!
//! # Grammar
//!
//! ```text
//! expr    = term { ("+" | "-") term } ;
//! term    = unary { ("*" | "/") unary } ;
//! unary   = ("-" | "+") unary | power ;
//! power   = atom [ "^" unary ] ;                  (* right-associative: 2^3^2 = 2^9 *)
//! atom    = number | "t" | "pi"
//!         | func "(" expr ")"                      (* sin cos tan abs sqrt exp log *)
//!         | ("min" | "max") "(" expr "," expr { "," expr } ")"
//!         | "if" "(" expr cmp expr "," expr "," expr ")"
//!         | "(" expr ")" ;
//! cmp     = "<" | "<=" | ">" | ">=" ;
//! number  = digits [ "." [ digits ] ] [ exponent ] | "." digits [ exponent ] ;
//! exponent = ("e" | "E") [ "+" | "-" ] digits ;
//! ```
//!
//! As in ordinary maths, `^` binds tighter than unary minus (`-t^2` is `-(t²)`) and a unary
//! minus may start an exponent (`2^-t`). Names are matched case-insensitively (`PI`, `Sin`),
//! `log` is the natural logarithm, angles are radians. A comparison can only appear as the
//! condition of `if`, which yields its second argument when the condition holds and its third
//! otherwise; a comparison with NaN is false. There is no implicit multiplication (`2t` is an
//! error, write `2*t`), no `**` (use `^`), no other names, no strings and nothing but ASCII.
//!
//! # Limits
//!
//! Sources are at most [`MAX_SOURCE_LEN`] bytes, programs at most [`MAX_NODES`] operations,
//! and parentheses, function calls, unary signs and exponents nest at most [`MAX_DEPTH`]
//! levels. The parser counts its own recursion against that depth, so 10,000 `(` give an
//! error instead of a stack overflow. Evaluation walks the postfix program once with an
//! explicit stack: no recursion, and the cost of one sample is exactly the program length.
//! Both branches of an `if` are evaluated (a select, not a jump), so the cost never depends on
//! `t`.
//!
//! # Non-finite values
//!
//! Intermediate values may be infinite or NaN (an `if` may discard them, as in
//! `if(t > 0, log(t), 0)` at `t = 0`), but a non-finite result is an error for that sample,
//! never clamped: clamping would silently turn a broken curve into a different, wrong one.
//!
//! Error positions are 0-based byte offsets into the source.

use std::fmt;

/// Longest accepted source, in bytes. Real curves need a few dozen characters; the limit only
/// stops abuse.
pub const MAX_SOURCE_LEN: usize = 512;
/// Most operations in a compiled program; this bounds the cost of evaluating one sample.
pub const MAX_NODES: usize = 256;
/// Deepest nesting of parentheses, calls, unary signs and exponents.
pub const MAX_DEPTH: usize = 32;
/// Most arguments of `min` and `max`.
pub const MAX_ARGS: usize = 16;

/// Why a source is not a valid expression. Every variant carries the byte offset it refers
/// to, except those about the source as a whole.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ExprError {
    /// Nothing but whitespace.
    #[error("the expression is empty")]
    Empty,
    /// The source is over [`MAX_SOURCE_LEN`] bytes.
    #[error("the expression is {len} bytes long; at most {MAX_SOURCE_LEN} are allowed")]
    TooLong {
        /// Length of the source in bytes.
        len: usize,
    },
    /// A character that no token starts with (including any non-ASCII character).
    #[error("unexpected character {ch:?} at {pos}")]
    UnexpectedChar {
        /// The character.
        ch: char,
        /// Its byte offset.
        pos: usize,
    },
    /// A name that is not `t`, `pi`, `if` or one of the functions.
    #[error("unknown name '{name}' at {pos}")]
    UnknownName {
        /// The name (cut to 40 characters).
        name: String,
        /// Its byte offset.
        pos: usize,
    },
    /// A number that does not parse or does not fit a finite `f64`.
    #[error("invalid number '{text}' at {pos}")]
    BadNumber {
        /// The number's text (cut to 40 characters).
        text: String,
        /// Its byte offset.
        pos: usize,
    },
    /// Python's power operator, which this language spells `^`.
    #[error("'**' at {pos}: write powers with '^'")]
    DoubleStar {
        /// Byte offset of the first `*`.
        pos: usize,
    },
    /// The parser needed something else here.
    #[error("expected {expected} at {pos}, found {found}")]
    Expected {
        /// What the grammar allows at this point.
        expected: &'static str,
        /// What is there.
        found: String,
        /// Byte offset.
        pos: usize,
    },
    /// A comparison outside the condition of an `if`.
    #[error("comparison at {pos}: comparisons are only allowed as the condition of if(a < b, then, else)")]
    StrayComparison {
        /// Byte offset of the comparison operator.
        pos: usize,
    },
    /// A function called with the wrong number of arguments.
    #[error("{name}() at {pos} takes {expected} argument(s), got {got}")]
    Arity {
        /// Function name.
        name: &'static str,
        /// What it takes, e.g. "1" or "2 to 16".
        expected: &'static str,
        /// How many were given.
        got: usize,
        /// Byte offset of the name.
        pos: usize,
    },
    /// Nesting beyond [`MAX_DEPTH`].
    #[error("the expression nests deeper than {MAX_DEPTH} levels at {pos}")]
    TooDeep {
        /// Byte offset where the limit was hit.
        pos: usize,
    },
    /// More than [`MAX_NODES`] operations.
    #[error("the expression has more than {MAX_NODES} operations (at {pos})")]
    TooManyNodes {
        /// Byte offset where the limit was hit.
        pos: usize,
    },
}

impl ExprError {
    /// The byte offset the error refers to; 0 for errors about the whole source.
    pub fn pos(&self) -> usize {
        match self {
            ExprError::Empty | ExprError::TooLong { .. } => 0,
            ExprError::UnexpectedChar { pos, .. }
            | ExprError::UnknownName { pos, .. }
            | ExprError::BadNumber { pos, .. }
            | ExprError::DoubleStar { pos }
            | ExprError::Expected { pos, .. }
            | ExprError::StrayComparison { pos }
            | ExprError::Arity { pos, .. }
            | ExprError::TooDeep { pos }
            | ExprError::TooManyNodes { pos } => *pos,
        }
    }
}

/// A sample whose value is NaN or infinite (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the expression is not finite at t = {t} (value {value})")]
pub struct NonFinite {
    /// The parameter value.
    pub t: f64,
    /// The non-finite result.
    pub value: f64,
}

/// One-argument functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Func {
    Sin,
    Cos,
    Tan,
    Abs,
    Sqrt,
    Exp,
    Log,
}

impl Func {
    fn apply(self, v: f64) -> f64 {
        match self {
            Func::Sin => v.sin(),
            Func::Cos => v.cos(),
            Func::Tan => v.tan(),
            Func::Abs => v.abs(),
            Func::Sqrt => v.sqrt(),
            Func::Exp => v.exp(),
            Func::Log => v.ln(),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Abs => "abs",
            Func::Sqrt => "sqrt",
            Func::Exp => "exp",
            Func::Log => "log",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cmp {
    Lt,
    Le,
    Gt,
    Ge,
}

impl Cmp {
    fn holds(self, a: f64, b: f64) -> bool {
        match self {
            Cmp::Lt => a < b,
            Cmp::Le => a <= b,
            Cmp::Gt => a > b,
            Cmp::Ge => a >= b,
        }
    }
}

/// One postfix operation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Const(f64),
    T,
    Neg,
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Call(Func),
    /// Pops this many values.
    Min(u8),
    Max(u8),
    /// Pops lhs, rhs, then, else; pushes then if `lhs cmp rhs`, else `else`.
    Select(Cmp),
}

impl Op {
    /// Values popped and pushed, for the stack-depth bound.
    fn arity(self) -> usize {
        match self {
            Op::Const(_) | Op::T => 0,
            Op::Neg | Op::Call(_) => 1,
            Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Pow => 2,
            Op::Min(n) | Op::Max(n) => n as usize,
            Op::Select(_) => 4,
        }
    }
}

/// A parsed, validated expression in `t`: a curve coordinate the LLM (or the built-in shape
/// library) wrote. Cheap to evaluate many times.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    source: String,
    ops: Vec<Op>,
    max_stack: usize,
}

impl Expr {
    /// Parses `source` (see the module documentation for the grammar and limits).
    pub fn parse(source: &str) -> Result<Expr, ExprError> {
        if source.len() > MAX_SOURCE_LEN {
            return Err(ExprError::TooLong { len: source.len() });
        }
        // A lexical error ends the token stream early; parsing that prefix first reports
        // whichever problem comes first in the text ("unknown name 'system' at 0" rather
        // than a complaint about a quote further on).
        let (tokens, lex_error) = lex(source);
        if tokens.len() == 1 && lex_error.is_none() {
            return Err(ExprError::Empty);
        }
        let parsed = Self::parse_tokens(&tokens).map(|e| Expr {
            source: source.to_string(),
            ..e
        });
        match (parsed, lex_error) {
            (Ok(e), None) => Ok(e),
            (Err(e), Some(lex)) if e.pos() < lex.pos() => Err(e),
            (_, Some(lex)) => Err(lex),
            (Err(e), None) => Err(e),
        }
    }

    fn parse_tokens(tokens: &[Token<'_>]) -> Result<Expr, ExprError> {
        let mut parser = Parser {
            tokens,
            at: 0,
            depth: 0,
            ops: Vec::new(),
        };
        parser.parse_sum()?;
        let next = parser.peek();
        match next.tok {
            Tok::End => {}
            Tok::Cmp(_) => return Err(ExprError::StrayComparison { pos: next.pos }),
            Tok::RParen => {
                return Err(ExprError::Expected {
                    expected: "end of expression (this ')' has no matching '(')",
                    found: next.tok.describe(),
                    pos: next.pos,
                })
            }
            _ => {
                return Err(ExprError::Expected {
                    expected: "an operator",
                    found: next.tok.describe(),
                    pos: next.pos,
                })
            }
        }
        let ops = parser.ops;
        let max_stack = stack_bound(&ops);
        Ok(Expr {
            source: String::new(),
            ops,
            max_stack,
        })
    }

    /// The source text as given.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of operations in the compiled program (the cost of one evaluation).
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// Whether the program is empty; never true for a parsed expression.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// Whether the value depends on `t` at all.
    pub fn uses_t(&self) -> bool {
        self.ops.contains(&Op::T)
    }

    /// The value at `t`, or an error if it is NaN or infinite.
    pub fn eval(&self, t: f64) -> Result<f64, NonFinite> {
        let value = self.eval_raw(t);
        if value.is_finite() {
            Ok(value)
        } else {
            Err(NonFinite { t, value })
        }
    }

    fn eval_raw(&self, t: f64) -> f64 {
        // The parser bounds the stack by MAX_NODES, so a fixed array needs no allocation.
        let mut stack = [0.0f64; MAX_NODES];
        let mut sp = 0usize;
        debug_assert!(self.max_stack <= MAX_NODES);
        for &op in &self.ops {
            let n = op.arity();
            let base = sp - n;
            let args = &stack[base..sp];
            let value = match op {
                Op::Const(c) => c,
                Op::T => t,
                Op::Neg => -args[0],
                Op::Add => args[0] + args[1],
                Op::Sub => args[0] - args[1],
                Op::Mul => args[0] * args[1],
                Op::Div => args[0] / args[1],
                Op::Pow => args[0].powf(args[1]),
                Op::Call(f) => f.apply(args[0]),
                // NaN propagates: a min over a NaN is not a number either.
                Op::Min(_) => args.iter().copied().fold(f64::INFINITY, |a, b| {
                    if a.is_nan() || b.is_nan() {
                        f64::NAN
                    } else {
                        a.min(b)
                    }
                }),
                Op::Max(_) => args.iter().copied().fold(f64::NEG_INFINITY, |a, b| {
                    if a.is_nan() || b.is_nan() {
                        f64::NAN
                    } else {
                        a.max(b)
                    }
                }),
                Op::Select(c) => {
                    if c.holds(args[0], args[1]) {
                        args[2]
                    } else {
                        args[3]
                    }
                }
            };
            stack[base] = value;
            sp = base + 1;
        }
        stack[0]
    }
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.source)
    }
}

impl std::str::FromStr for Expr {
    type Err = ExprError;

    fn from_str(s: &str) -> Result<Expr, ExprError> {
        Expr::parse(s)
    }
}

/// The deepest the evaluation stack gets.
fn stack_bound(ops: &[Op]) -> usize {
    let mut sp = 0usize;
    let mut max = 0usize;
    for op in ops {
        sp = sp - op.arity() + 1;
        max = max.max(sp);
    }
    max
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Tok<'a> {
    Num(f64),
    Name(&'a str),
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    LParen,
    RParen,
    Comma,
    Cmp(Cmp),
    End,
}

impl Tok<'_> {
    fn describe(&self) -> String {
        match self {
            Tok::Num(v) => format!("the number {v}"),
            Tok::Name(n) => format!("'{}'", clip(n)),
            Tok::Plus => "'+'".into(),
            Tok::Minus => "'-'".into(),
            Tok::Star => "'*'".into(),
            Tok::Slash => "'/'".into(),
            Tok::Caret => "'^'".into(),
            Tok::LParen => "'('".into(),
            Tok::RParen => "')'".into(),
            Tok::Comma => "','".into(),
            Tok::Cmp(Cmp::Lt) => "'<'".into(),
            Tok::Cmp(Cmp::Le) => "'<='".into(),
            Tok::Cmp(Cmp::Gt) => "'>'".into(),
            Tok::Cmp(Cmp::Ge) => "'>='".into(),
            Tok::End => "the end of the expression".into(),
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Token<'a> {
    tok: Tok<'a>,
    pos: usize,
}

/// Error messages quote user text; a cap keeps a 500-byte name from flooding them.
fn clip(s: &str) -> String {
    s.chars().take(40).collect()
}

/// The tokens of `src`, ending with [`Tok::End`]; at the first lexical error the stream ends
/// there and the error is returned beside it.
fn lex(src: &str) -> (Vec<Token<'_>>, Option<ExprError>) {
    let bytes = src.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let b = bytes[i];
        let pos = i;
        let single = match b {
            b' ' | b'\t' | b'\n' | b'\r' => {
                i += 1;
                continue;
            }
            b'+' => Some(Tok::Plus),
            b'-' => Some(Tok::Minus),
            b'/' => Some(Tok::Slash),
            b'^' => Some(Tok::Caret),
            b'(' => Some(Tok::LParen),
            b')' => Some(Tok::RParen),
            b',' => Some(Tok::Comma),
            b'*' => {
                if bytes.get(i + 1) == Some(&b'*') {
                    return finish(out, pos, Some(ExprError::DoubleStar { pos }));
                }
                Some(Tok::Star)
            }
            _ => None,
        };
        if let Some(tok) = single {
            out.push(Token { tok, pos });
            i += 1;
            continue;
        }
        if b == b'<' || b == b'>' {
            let or_equal = bytes.get(i + 1) == Some(&b'=');
            let cmp = match (b, or_equal) {
                (b'<', false) => Cmp::Lt,
                (b'<', true) => Cmp::Le,
                (_, false) => Cmp::Gt,
                (_, true) => Cmp::Ge,
            };
            out.push(Token {
                tok: Tok::Cmp(cmp),
                pos,
            });
            i += 1 + or_equal as usize;
            continue;
        }
        if b.is_ascii_digit() || (b == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            let end = number_end(bytes, i);
            let text = &src[i..end];
            let value = match text.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                _ => {
                    let error = ExprError::BadNumber {
                        text: clip(text),
                        pos,
                    };
                    return finish(out, pos, Some(error));
                }
            };
            out.push(Token {
                tok: Tok::Num(value),
                pos,
            });
            i = end;
            continue;
        }
        if b.is_ascii_alphabetic() || b == b'_' {
            let mut end = i;
            while end < bytes.len() && (bytes[end].is_ascii_alphanumeric() || bytes[end] == b'_') {
                end += 1;
            }
            out.push(Token {
                tok: Tok::Name(&src[i..end]),
                pos,
            });
            i = end;
            continue;
        }
        // `i` is always at a character boundary: every branch above consumes ASCII only.
        let ch = src[i..].chars().next().unwrap_or('\u{fffd}');
        return finish(out, pos, Some(ExprError::UnexpectedChar { ch, pos }));
    }
    finish(out, bytes.len(), None)
}

fn finish(
    mut tokens: Vec<Token<'_>>,
    pos: usize,
    error: Option<ExprError>,
) -> (Vec<Token<'_>>, Option<ExprError>) {
    tokens.push(Token { tok: Tok::End, pos });
    (tokens, error)
}

/// End of the number starting at `i`: digits, an optional fraction, an optional exponent. A
/// dangling `e` (as in `2e` or `2e+`) is included so that `str::parse` rejects it, rather
/// than being read as a name after a number.
fn number_end(bytes: &[u8], mut i: usize) -> usize {
    let digits = |mut i: usize| {
        while i < bytes.len() && bytes[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    i = digits(i);
    if bytes.get(i) == Some(&b'.') {
        i = digits(i + 1);
    }
    if matches!(bytes.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        if matches!(bytes.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let k = digits(j);
        // "2exp(t)" would otherwise be swallowed as a broken number; only a letter run that is
        // not a name keeps the 'e'.
        let is_name = bytes
            .get(i + 1)
            .is_some_and(|c| c.is_ascii_alphabetic() || *c == b'_');
        i = if is_name { i } else { k };
    }
    i
}

struct Parser<'a, 'b> {
    tokens: &'b [Token<'a>],
    at: usize,
    depth: usize,
    ops: Vec<Op>,
}

impl<'a> Parser<'a, '_> {
    fn peek(&self) -> Token<'a> {
        self.tokens[self.at]
    }

    fn bump(&mut self) -> Token<'a> {
        let t = self.tokens[self.at];
        if !matches!(t.tok, Tok::End) {
            self.at += 1;
        }
        t
    }

    fn emit(&mut self, op: Op, pos: usize) -> Result<(), ExprError> {
        if self.ops.len() >= MAX_NODES {
            return Err(ExprError::TooManyNodes { pos });
        }
        self.ops.push(op);
        Ok(())
    }

    fn expect(
        &mut self,
        want: Tok<'static>,
        expected: &'static str,
    ) -> Result<Token<'a>, ExprError> {
        let t = self.bump();
        if std::mem::discriminant(&t.tok) == std::mem::discriminant(&want) {
            Ok(t)
        } else {
            Err(ExprError::Expected {
                expected,
                found: t.tok.describe(),
                pos: t.pos,
            })
        }
    }

    fn parse_sum(&mut self) -> Result<(), ExprError> {
        self.parse_product()?;
        loop {
            let t = self.peek();
            let op = match t.tok {
                Tok::Plus => Op::Add,
                Tok::Minus => Op::Sub,
                _ => return Ok(()),
            };
            self.bump();
            self.parse_product()?;
            self.emit(op, t.pos)?;
        }
    }

    fn parse_product(&mut self) -> Result<(), ExprError> {
        self.parse_unary()?;
        loop {
            let t = self.peek();
            let op = match t.tok {
                Tok::Star => Op::Mul,
                Tok::Slash => Op::Div,
                _ => return Ok(()),
            };
            self.bump();
            self.parse_unary()?;
            self.emit(op, t.pos)?;
        }
    }

    /// Every path of recursion passes through here, so this is where depth is counted.
    fn parse_unary(&mut self) -> Result<(), ExprError> {
        let t = self.peek();
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(ExprError::TooDeep { pos: t.pos });
        }
        match t.tok {
            Tok::Minus => {
                self.bump();
                self.parse_unary()?;
                self.emit(Op::Neg, t.pos)?;
            }
            Tok::Plus => {
                self.bump();
                self.parse_unary()?;
            }
            _ => self.parse_power()?,
        }
        self.depth -= 1;
        Ok(())
    }

    fn parse_power(&mut self) -> Result<(), ExprError> {
        self.parse_atom()?;
        let t = self.peek();
        if matches!(t.tok, Tok::Caret) {
            self.bump();
            self.parse_unary()?;
            self.emit(Op::Pow, t.pos)?;
        }
        Ok(())
    }

    fn parse_atom(&mut self) -> Result<(), ExprError> {
        let t = self.bump();
        match t.tok {
            Tok::Num(v) => self.emit(Op::Const(v), t.pos)?,
            Tok::LParen => {
                self.parse_sum()?;
                self.close()?;
            }
            Tok::Name(name) => self.parse_name(name, t.pos)?,
            _ => {
                return Err(ExprError::Expected {
                    expected: "a number, 't', 'pi', a function or '('",
                    found: t.tok.describe(),
                    pos: t.pos,
                })
            }
        }
        // A value directly followed by another value is almost always a forgotten '*'.
        let next = self.peek();
        if matches!(next.tok, Tok::Num(_) | Tok::Name(_) | Tok::LParen) {
            return Err(ExprError::Expected {
                expected: "an operator (write '2*t', not '2t')",
                found: next.tok.describe(),
                pos: next.pos,
            });
        }
        Ok(())
    }

    fn close(&mut self) -> Result<(), ExprError> {
        let t = self.bump();
        match t.tok {
            Tok::RParen => Ok(()),
            Tok::Cmp(_) => Err(ExprError::StrayComparison { pos: t.pos }),
            _ => Err(ExprError::Expected {
                expected: "')'",
                found: t.tok.describe(),
                pos: t.pos,
            }),
        }
    }

    fn parse_name(&mut self, name: &'a str, pos: usize) -> Result<(), ExprError> {
        let lower = name.to_ascii_lowercase();
        let func = match lower.as_str() {
            "t" => return self.emit(Op::T, pos),
            "pi" => return self.emit(Op::Const(std::f64::consts::PI), pos),
            "sin" => Func::Sin,
            "cos" => Func::Cos,
            "tan" => Func::Tan,
            "abs" => Func::Abs,
            "sqrt" => Func::Sqrt,
            "exp" => Func::Exp,
            "log" => Func::Log,
            "min" | "max" => return self.parse_min_max(lower == "min", pos),
            "if" => return self.parse_if(pos),
            _ => {
                return Err(ExprError::UnknownName {
                    name: clip(name),
                    pos,
                })
            }
        };
        self.expect(Tok::LParen, "'(' after a function name")?;
        let args = self.parse_args()?;
        if args != 1 {
            return Err(ExprError::Arity {
                name: func.name(),
                expected: "1",
                got: args,
                pos,
            });
        }
        self.emit(Op::Call(func), pos)
    }

    /// Comma-separated expressions up to the closing ')'; returns how many.
    fn parse_args(&mut self) -> Result<usize, ExprError> {
        if matches!(self.peek().tok, Tok::RParen) {
            self.bump();
            return Ok(0);
        }
        let mut n = 0;
        loop {
            self.parse_sum()?;
            n += 1;
            let t = self.peek();
            match t.tok {
                Tok::Comma => {
                    self.bump();
                }
                _ => {
                    self.close()?;
                    return Ok(n);
                }
            }
        }
    }

    fn parse_min_max(&mut self, is_min: bool, pos: usize) -> Result<(), ExprError> {
        let name = if is_min { "min" } else { "max" };
        self.expect(Tok::LParen, "'(' after a function name")?;
        let args = self.parse_args()?;
        if !(2..=MAX_ARGS).contains(&args) {
            return Err(ExprError::Arity {
                name,
                expected: "2 to 16",
                got: args,
                pos,
            });
        }
        let n = args as u8;
        self.emit(if is_min { Op::Min(n) } else { Op::Max(n) }, pos)
    }

    fn parse_if(&mut self, pos: usize) -> Result<(), ExprError> {
        self.expect(Tok::LParen, "'(' after 'if'")?;
        self.parse_sum()?;
        let t = self.bump();
        let cmp = match t.tok {
            Tok::Cmp(c) => c,
            _ => {
                return Err(ExprError::Expected {
                    expected: "a comparison (<, <=, >, >=) as the condition of if",
                    found: t.tok.describe(),
                    pos: t.pos,
                })
            }
        };
        self.parse_sum()?;
        for _ in 0..2 {
            self.expect(
                Tok::Comma,
                "',' between the arguments of if(cond, then, else)",
            )?;
            self.parse_sum()?;
        }
        let t = self.peek();
        if matches!(t.tok, Tok::Comma) {
            return Err(ExprError::Arity {
                name: "if",
                expected: "3 (a comparison, then, else)",
                got: 4,
                pos,
            });
        }
        self.close()?;
        self.emit(Op::Select(cmp), pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use std::f64::consts::PI;

    fn eval(src: &str, t: f64) -> f64 {
        Expr::parse(src)
            .unwrap_or_else(|e| panic!("{src:?}: {e}"))
            .eval(t)
            .unwrap_or_else(|e| panic!("{src:?}: {e}"))
    }

    #[test]
    fn valid_expressions_match_reference_values() {
        let cases: &[(&str, f64, f64)] = &[
            ("1", 0.0, 1.0),
            ("t", 2.5, 2.5),
            ("T", 2.5, 2.5),
            ("pi", 0.0, PI),
            ("2*PI", 0.0, 2.0 * PI),
            ("1.5e2", 0.0, 150.0),
            ("2.5E-1", 0.0, 0.25),
            (".5", 0.0, 0.5),
            ("5.", 0.0, 5.0),
            ("1 + 2 * 3", 0.0, 7.0),
            ("(1 + 2) * 3", 0.0, 9.0),
            ("10 - 4 - 3", 0.0, 3.0),
            ("8 / 4 / 2", 0.0, 1.0),
            ("2^3^2", 0.0, 512.0),
            ("(2^3)^2", 0.0, 64.0),
            ("-t^2", 3.0, -9.0),
            ("2^-1", 0.0, 0.5),
            ("--t", 4.0, 4.0),
            ("+t", 4.0, 4.0),
            ("-(t - 1)", 4.0, -3.0),
            ("sin(t)", 0.5, 0.5f64.sin()),
            ("cos(2*t)", 0.3, 0.6f64.cos()),
            ("Sin(pi/2)", 0.0, 1.0),
            ("tan(t)", 0.4, 0.4f64.tan()),
            ("abs(-3*t)", 2.0, 6.0),
            ("sqrt(t)", 9.0, 3.0),
            ("exp(1)", 0.0, std::f64::consts::E),
            ("log(exp(t))", 1.7, 1.7),
            ("min(t, 2)", 5.0, 2.0),
            ("max(t, 2, 7, -1)", 5.0, 7.0),
            ("min(3, t, 1 + 1)", 5.0, 2.0),
            ("if(t < 1, 10, 20)", 0.5, 10.0),
            ("if(t < 1, 10, 20)", 1.0, 20.0),
            ("if(t <= 1, 10, 20)", 1.0, 10.0),
            ("if(t > 1, 10, 20)", 1.0, 20.0),
            ("if(t >= 1, 10, 20)", 1.0, 10.0),
            ("if(t > 0, log(t), 0)", 0.0, 0.0),
            ("if(t < 1, t, if(t < 2, 1, 3 - t))", 2.5, 0.5),
            ("if(sin(t) + 1 < 2*t, t^2, -t)", 3.0, 9.0),
            ("1 - cos(t)", PI, 2.0),
            ("  t\n*\t2 ", 3.0, 6.0),
            ("3 + if(t<0,1,2)*2", 1.0, 7.0),
        ];
        for &(src, t, want) in cases {
            let got = eval(src, t);
            assert!(
                (got - want).abs() <= 1e-12 * want.abs().max(1.0),
                "{src:?} at {t}: {got} != {want}"
            );
        }
    }

    #[test]
    fn hostile_and_malformed_inputs_are_rejected() {
        let deep_parens = "(".repeat(10_000) + "t" + &")".repeat(10_000);
        let just_parens = "(".repeat(10_000);
        let minus_chain = "-".repeat(400) + "t";
        let nested_sin = "sin(".repeat(300) + "t" + &")".repeat(300);
        let pow_chain = "t^".repeat(200) + "t";
        let long_sum = "t+".repeat(200) + "t";
        let long_name = "a".repeat(600);
        let long_min = format!("min({})", vec!["t"; 17].join(","));
        let cases: Vec<&str> = vec![
            "",
            "   ",
            "system('rm -rf /')",
            "eval(t)",
            "import os",
            "__import__('os').system('ls')",
            "__proto__",
            "constructor.constructor('alert(1)')()",
            "this",
            "window.alert(1)",
            "process.exit()",
            "t; t",
            "`t`",
            "\"t\"",
            "'t'",
            "t.x",
            "x",
            "e",
            "inf",
            "NaN",
            "Infinity",
            "1e999",
            "sin",
            "sin()",
            "sin(t, t)",
            "sin t",
            "min(t)",
            "max()",
            long_min.as_str(),
            "if(t, 1, 2)",
            "if(t < 1, 2)",
            "if(t < 1, 2, 3, 4)",
            "if t < 1 then 1 else 2",
            "t < 1",
            "if(1 < 2 < 3, 1, 2)",
            "if(t<1,1,2) < 3",
            "(t < 1)",
            "((t)",
            "t)",
            "()",
            deep_parens.as_str(),
            just_parens.as_str(),
            minus_chain.as_str(),
            nested_sin.as_str(),
            pow_chain.as_str(),
            long_sum.as_str(),
            long_name.as_str(),
            "t+",
            "+",
            "*t",
            "t**2",
            "2t",
            "2pi",
            "t(2)",
            "t t",
            "1..2",
            "1.2.3",
            "0x10",
            "1e",
            "1e+",
            "πt",
            "2*π",
            "ｔ",
            "t\u{200b}",
            "t\u{0}",
            "t\u{202e}",
            "t = 1",
            "t == 1",
            "t != 1",
            "!t",
            "t && 1",
            "t || 1",
            "t % 2",
            "[t]",
            "{t}",
            "t, 1",
            "log(t",
            "$t",
            "#t",
            "@t",
            "\\t",
            "<script>alert(1)</script>",
            "1/",
            "t^",
            "cos(t))",
            "sin(t)cos(t)",
            "if",
            "if()",
            "min",
            "abs(,)",
            "max(t,)",
            "exp(t)\u{1b}[2J",
        ];
        assert!(cases.len() >= 40);
        for src in cases {
            let result = std::panic::catch_unwind(|| Expr::parse(src));
            match result {
                Ok(Err(e)) => {
                    let msg = e.to_string();
                    assert!(!msg.is_empty());
                }
                Ok(Ok(e)) => panic!("{:?} was accepted as {:?}", clip(src), e.ops),
                Err(_) => panic!("{:?} panicked", clip(src)),
            }
        }
    }

    #[test]
    fn errors_name_the_problem_and_its_position() {
        let msg = |s: &str| Expr::parse(s).unwrap_err().to_string();
        assert_eq!(msg("1 + system(t)"), "unknown name 'system' at 4");
        assert_eq!(msg("t + π"), "unexpected character 'π' at 4");
        assert_eq!(msg("t**2"), "'**' at 1: write powers with '^'");
        assert!(msg("2t").contains("at 1"), "{}", msg("2t"));
        assert!(msg("t < 1").starts_with("comparison at 2"));
        assert!(msg("min(t)").contains("min() at 0 takes 2 to 16"));
        assert!(msg(&"(".repeat(100)).contains("nests deeper"));
        assert!(matches!(
            Expr::parse(&"t+".repeat(200)),
            Err(ExprError::TooManyNodes { .. })
        ));
        assert!(matches!(
            Expr::parse(&" ".repeat(600)),
            Err(ExprError::TooLong { len: 600 })
        ));
        assert!(matches!(Expr::parse("  "), Err(ExprError::Empty)));
    }

    #[test]
    fn limits_are_generous_enough_for_real_curves() {
        let nested = "(".repeat(MAX_DEPTH - 1) + "t" + &")".repeat(MAX_DEPTH - 1);
        assert_eq!(eval(&nested, 2.0), 2.0);
        let sum = "t+".repeat(100) + "t";
        assert_eq!(eval(&sum, 1.0), 101.0);
    }

    #[test]
    fn non_finite_results_are_errors_but_intermediates_may_be_discarded() {
        let e = Expr::parse("log(t)").unwrap();
        assert!(e.eval(0.0).is_err());
        assert!(e.eval(-1.0).is_err());
        assert!(Expr::parse("1/t").unwrap().eval(0.0).is_err());
        assert!(Expr::parse("exp(exp(exp(t)))").unwrap().eval(10.0).is_err());
        assert!(Expr::parse("min(t, sqrt(-1))").unwrap().eval(0.0).is_err());
        assert_eq!(Expr::parse("if(t > 0, 1/t, 0)").unwrap().eval(0.0), Ok(0.0));
        assert!(Expr::parse("t").unwrap().eval(f64::NAN).is_err());
    }

    #[test]
    fn stack_bound_is_respected() {
        for src in ["1+(2+(3+(4+(5+t))))", "max(1,2,3,4,5,6,7,t)", "if(t<1,t,t)"] {
            let e = Expr::parse(src).unwrap();
            assert!(e.max_stack <= e.len());
        }
    }

    /// Random bytes and mutated valid expressions: parsing and evaluating never panic.
    #[test]
    fn random_and_mutated_strings_never_panic() {
        const SEEDS: &[&str] = &[
            "1 - cos(t)",
            "if(t < pi, 1 - cos(t), 3 + cos(t))",
            "2^-t*sin(3*t) + max(t, 1, 2)",
            "(1 + 2/(4*pi)*(t - sin(t)))*cos(t)",
            "min(abs(t), sqrt(t), log(t + 1), exp(-t^2), tan(t/3))",
        ];
        const ALPHABET: &[u8] = b"0123456789.eE+-*/^(),<>= tpisncoaqrxlgmfTPI_;`'\"\\";
        let mut rng = Rng::new(20_240_611);
        let mut accepted = 0usize;
        for round in 0..100_000usize {
            let text: String = if round % 4 == 0 {
                let len = rng.below(40);
                let bytes: Vec<u8> = (0..len).map(|_| rng.next_u32() as u8).collect();
                String::from_utf8_lossy(&bytes).into_owned()
            } else {
                let mut bytes = SEEDS[rng.below(SEEDS.len())].as_bytes().to_vec();
                for _ in 0..1 + rng.below(4) {
                    let at = rng.below(bytes.len() + 1);
                    let c = ALPHABET[rng.below(ALPHABET.len())];
                    match rng.below(3) {
                        0 => bytes.insert(at, c),
                        1 if at < bytes.len() => {
                            bytes.remove(at);
                        }
                        _ if at < bytes.len() => bytes[at] = c,
                        _ => bytes.push(c),
                    }
                }
                String::from_utf8_lossy(&bytes).into_owned()
            };
            if let Ok(e) = Expr::parse(&text) {
                accepted += 1;
                assert!(e.len() <= MAX_NODES && e.max_stack <= MAX_NODES);
                for t in [-1.0, 0.0, 0.5, 3.0, 1e6] {
                    let _ = e.eval(t);
                }
            }
        }
        // The mutations must exercise the evaluator too, not only the error paths.
        assert!(accepted > 1000, "only {accepted} accepted");
    }
}
