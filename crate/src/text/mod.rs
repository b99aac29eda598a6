//! Text: the WordPiece tokenizer and the all-MiniLM-L6-v2 sentence encoder whose embeddings
//! condition the motion model.

pub mod minilm;
pub mod tokenizer;
