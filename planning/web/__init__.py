"""The browser page of ``pressplan serve`` (optional extra ``web``): a Flask server and a static page."""
