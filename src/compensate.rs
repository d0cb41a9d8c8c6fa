//! Swing-angle error identification and compensation (seed 003).
