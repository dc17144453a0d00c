"""Reports: agreement and efficiency tables, the demo pipeline and its HTML page."""
