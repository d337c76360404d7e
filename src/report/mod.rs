pub mod heatmap;
